#pragma once
// MPI for `orrery study`, loaded at run time: the orrery program does not link MPI; an
// MpiSession loads the plugin liborrery_study_mpi.so (mpi_plugin_api.h) with dlopen and calls
// MPI_Init through it. Without an MPI launch nothing of MPI is touched, so the program runs on
// machines without Open MPI; a missing plugin or library is a one-line error naming the Debian
// packages, only when MPI is asked for.
//
// An MPI launch is recognized by the variables launchers give each process: OMPI_COMM_WORLD_SIZE
// (Open MPI's mpirun), PMIX_RANK (PMIx: Open MPI, srun --mpi=pmix), PMI_RANK / PMI_SIZE (Hydra,
// srun --mpi=pmi2). `srun` with several tasks but none of these would start independent copies
// of the study on one folder; that is refused (MisconfiguredLaunch).
//
// The plugin is looked for in $ORRERY_STUDY_MPI_PLUGIN, then beside the program: ../lib/orrery/,
// ../lib/ and the program's own folder (the build tree has build/bin/orrery and
// build/lib/liborrery_study_mpi.so; an installed tree bin/ and lib/orrery/).
//
// Usage:
//   if (MpiLaunchDetected(nullptr)) {
//     std::unique_ptr<MpiSession> mpi = MpiSession::Start();
//     if (mpi->rank() == 0) ...
//   }
#include <memory>
#include <optional>
#include <string>
#include <string_view>

struct OrreryStudyMpi;

namespace orrery::study {

// Whether an MPI launcher started this process; `evidence` (if given) receives the variable that
// says so ("OMPI_COMM_WORLD_SIZE=2").
bool MpiLaunchDetected(std::string* evidence);

// The reason to refuse a launch that would run several uncoordinated copies (srun -n N without
// PMI), else nullopt.
std::optional<std::string> MisconfiguredLaunch();

struct MpiMessage {
  int source = 0;
  int tag = 0;
  std::string data;
};

class MpiSession {
 public:
  // Loads the plugin and initializes MPI. Throws std::runtime_error with one line naming what is
  // missing (the plugin, the MPI library) or MPI's own message.
  static std::unique_ptr<MpiSession> Start();
  ~MpiSession();  // MPI_Finalize
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  int local_size() const { return local_size_; }  // ranks on this node
  const std::string& library() const { return library_; }

  // Throws std::runtime_error when MPI reports an error.
  void Send(int destination, int tag, std::string_view data) const;
  // A waiting message from any rank, received; nullopt when none waits.
  std::optional<MpiMessage> TryReceive() const;
  // Waits for a message (polling every few milliseconds).
  MpiMessage Receive() const;
  // MPI_Abort: ends every rank.
  [[noreturn]] void Abort(int code) const;

 private:
  MpiSession() = default;
  void* handle_ = nullptr;
  const OrreryStudyMpi* api_ = nullptr;
  int rank_ = 0, size_ = 1, local_size_ = 1;
  std::string library_;
};

// Where the plugin would be loaded from (the first candidate that exists), "" if none does.
std::string FindMpiPlugin();

}  // namespace orrery::study
