// The MPI plugin of `orrery study` (mpi_plugin_api.h): the only file of the project that
// includes <mpi.h>; built as the module liborrery_study_mpi.so, linked against MPI, loaded by the
// orrery program with dlopen when a study runs under an MPI launcher.
#include <mpi.h>

#include <cstdio>
#include <cstring>

#include "tools/study/mpi_plugin_api.h"

namespace {

void Copy(const char* text, char* out, int size) {
  if (out == nullptr || size <= 0) return;
  std::snprintf(out, static_cast<std::size_t>(size), "%s", text);
}

// The MPI error string of `code`
void ErrorText(int code, const char* what, char* out, int size) {
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  if (MPI_Error_string(code, text, &length) != MPI_SUCCESS)
    std::snprintf(text, sizeof text, "error %d", code);
  char message[MPI_MAX_ERROR_STRING + 64];
  std::snprintf(message, sizeof message, "%s: %s", what, text);
  Copy(message, out, size);
}

int Init(int* rank, int* size, int* local_size, char* library, int library_size, char* error,
         int error_size) {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) {
    int provided = 0;
    const int rc = MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SINGLE, &provided);
    if (rc != MPI_SUCCESS) {
      ErrorText(rc, "MPI_Init_thread", error, error_size);
      return 1;
    }
  }
  // Errors are returned, not fatal: the study reports them
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(MPI_COMM_WORLD, rank);
  MPI_Comm_size(MPI_COMM_WORLD, size);
  MPI_Comm node;
  if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) ==
      MPI_SUCCESS) {
    MPI_Comm_size(node, local_size);
    MPI_Comm_free(&node);
  } else {
    *local_size = 1;
  }
  char version[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(version, &length);
  // "Open MPI v4.1.4, package: ..." -> "Open MPI v4.1.4"
  if (char* end = std::strpbrk(version, ",\n")) *end = '\0';
  Copy(version, library, library_size);
  return 0;
}

int Finalize() { return MPI_Finalize() == MPI_SUCCESS ? 0 : 1; }

void Abort(int code) { MPI_Abort(MPI_COMM_WORLD, code); }

int Send(const void* data, int bytes, int destination, int tag) {
  return MPI_Send(data, bytes, MPI_BYTE, destination, tag, MPI_COMM_WORLD) == MPI_SUCCESS ? 0 : 1;
}

int Probe(int* found, int* source, int* tag, int* bytes) {
  MPI_Status status;
  if (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, found, &status) != MPI_SUCCESS)
    return 1;
  if (*found) {
    *source = status.MPI_SOURCE;
    *tag = status.MPI_TAG;
    MPI_Get_count(&status, MPI_BYTE, bytes);
  }
  return 0;
}

int Receive(void* data, int bytes, int source, int tag, int* received) {
  MPI_Status status;
  if (MPI_Recv(data, bytes, MPI_BYTE, source, tag, MPI_COMM_WORLD, &status) != MPI_SUCCESS)
    return 1;
  MPI_Get_count(&status, MPI_BYTE, received);
  return 0;
}

const OrreryStudyMpi kApi{kOrreryStudyMpiAbi, Init, Finalize, Abort, Send, Probe, Receive};

}  // namespace

extern "C" __attribute__((visibility("default"))) const OrreryStudyMpi* orrery_study_mpi(void) {
  return &kApi;
}
