#include "tools/study/mpi_session.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "tools/study/mpi_plugin_api.h"
#include "tools/study/run_process.h"

namespace orrery::study {
namespace fs = std::filesystem;
namespace {

constexpr const char* kPluginName = "liborrery_study_mpi.so";

std::string Env(const char* name) {
  const char* v = std::getenv(name);
  return v == nullptr ? "" : v;
}

}  // namespace

bool MpiLaunchDetected(std::string* evidence) {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (const char* v = std::getenv(name)) {
      if (evidence != nullptr) *evidence = std::string(name) + "=" + v;
      return true;
    }
  return false;
}

std::optional<std::string> MisconfiguredLaunch() {
  const std::string tasks = Env("SLURM_STEP_NUM_TASKS");
  if (MpiLaunchDetected(nullptr) || tasks.empty() || std::atoi(tasks.c_str()) <= 1)
    return std::nullopt;
  return "started by srun as one of " + tasks +
         " tasks without MPI (no PMI in the environment): the copies would run the same study "
         "side by side; use `srun --mpi=pmix` (or pmi2) or mpirun";
}

std::string FindMpiPlugin() {
  if (const std::string explicit_path = Env("ORRERY_STUDY_MPI_PLUGIN"); !explicit_path.empty())
    return explicit_path;
  std::error_code ec;
  fs::path exe_dir;
  try {
    exe_dir = fs::path(SelfExecutable()).parent_path();
  } catch (const std::exception&) {
    return "";
  }
  for (const fs::path& p : {exe_dir / ".." / "lib" / "orrery" / kPluginName,
                            exe_dir / ".." / "lib" / kPluginName, exe_dir / kPluginName})
    if (fs::exists(p, ec)) return p.lexically_normal().string();
  return "";
}

std::unique_ptr<MpiSession> MpiSession::Start() {
  // The plugin, and the MPI library it links
  const std::string plugin = FindMpiPlugin();
  if (plugin.empty())
    throw std::runtime_error(
        std::string("MPI asked for, but ") + kPluginName +
        " is not beside the orrery program: build it with Open MPI present (Debian "
        "libopenmpi-dev), or set ORRERY_STUDY_MPI_PLUGIN");
  // RTLD_GLOBAL: Open MPI's own components look up its symbols
  void* handle = dlopen(plugin.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (handle == nullptr) {
    const char* why = dlerror();
    throw std::runtime_error("MPI asked for, but the MPI plugin " + plugin + " does not load (" +
                             (why != nullptr ? why : "unknown reason") +
                             "): install Open MPI (Debian libopenmpi3 and openmpi-bin)");
  }
  auto entry = reinterpret_cast<const OrreryStudyMpi* (*)()>(dlsym(handle, kOrreryStudyMpiEntry));
  const OrreryStudyMpi* api = entry != nullptr ? entry() : nullptr;
  if (api == nullptr || api->abi_version != kOrreryStudyMpiAbi) {
    dlclose(handle);
    throw std::runtime_error("the MPI plugin " + plugin +
                             " does not belong to this orrery program (rebuild it)");
  }
  // MPI_Init
  std::unique_ptr<MpiSession> s(new MpiSession());
  s->handle_ = handle;
  s->api_ = api;
  char library[256] = {0}, error[512] = {0};
  if (api->init(&s->rank_, &s->size_, &s->local_size_, library, sizeof library, error,
                sizeof error) != 0) {
    s->api_ = nullptr;  // not initialized: nothing to finalize
    throw std::runtime_error(std::string("MPI could not start: ") + error);
  }
  s->library_ = library;
  return s;
}

MpiSession::~MpiSession() {
  if (api_ != nullptr) api_->finalize();
  // The library stays loaded: MPI cannot be initialized twice, and its threads may still unwind
}

void MpiSession::Send(int destination, int tag, std::string_view data) const {
  if (api_->send(data.data(), static_cast<int>(data.size()), destination, tag) != 0)
    throw std::runtime_error("MPI: sending a message to rank " + std::to_string(destination) +
                             " failed");
}

std::optional<MpiMessage> MpiSession::TryReceive() const {
  int found = 0, source = 0, tag = 0, bytes = 0;
  if (api_->probe(&found, &source, &tag, &bytes) != 0)
    throw std::runtime_error("MPI: probing for messages failed");
  if (!found) return std::nullopt;
  MpiMessage m;
  m.source = source;
  m.tag = tag;
  m.data.resize(static_cast<std::size_t>(bytes));
  int received = 0;
  if (api_->receive(m.data.data(), bytes, source, tag, &received) != 0)
    throw std::runtime_error("MPI: receiving a message from rank " + std::to_string(source) +
                             " failed");
  m.data.resize(static_cast<std::size_t>(received));
  return m;
}

MpiMessage MpiSession::Receive() const {
  for (;;) {
    if (std::optional<MpiMessage> m = TryReceive()) return *m;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void MpiSession::Abort(int code) const {
  api_->abort(code);
  std::_Exit(code);
}

}  // namespace orrery::study
