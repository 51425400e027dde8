#pragma once
// The C interface between `orrery study` and its MPI plugin (liborrery_study_mpi.so, made from
// tools/study/mpi_plugin.cpp, the only file that includes <mpi.h>). The orrery program does not
// link MPI: it loads the plugin with dlopen when a study is started by an MPI launcher (or with
// --mpi), so the same program runs everywhere else without an MPI library installed, and a
// missing MPI is an error only when MPI is asked for (mpi_session.h).
//
// Every function returns 0 on success, else non-zero with a message in `error` (at most
// `error_size` bytes, NUL-terminated) where it takes one. Messages are byte strings of any
// length within an int; tags are the study's (study_mpi.h).
#include <cstddef>

extern "C" {

struct OrreryStudyMpi {
  int abi_version;  // kOrreryStudyMpiAbi
  // MPI_Init (with MPI_THREAD_SINGLE); rank and size in MPI_COMM_WORLD; `local_size` the ranks
  // on this node (MPI_Comm_split_type with MPI_COMM_TYPE_SHARED); `library` the MPI library's
  // version string (MPI_Get_library_version, up to its first comma or line end).
  int (*init)(int* rank, int* size, int* local_size, char* library, int library_size, char* error,
              int error_size);
  int (*finalize)(void);
  void (*abort)(int code);
  // Blocking standard-mode send of `bytes` bytes to `destination` with `tag`.
  int (*send)(const void* data, int bytes, int destination, int tag);
  // Non-blocking probe for any message from any source: *found 1 when one waits, with its
  // source, tag and size in bytes.
  int (*probe)(int* found, int* source, int* tag, int* bytes);
  // Blocking receive of a message from `source` with `tag` into `data` (capacity `bytes`);
  // *received the bytes it held.
  int (*receive)(void* data, int bytes, int source, int tag, int* received);
};

// Exported by the plugin: the function table.
const OrreryStudyMpi* orrery_study_mpi(void);

}  // extern "C"

inline constexpr int kOrreryStudyMpiAbi = 1;
inline constexpr const char* kOrreryStudyMpiEntry = "orrery_study_mpi";
