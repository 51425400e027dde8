#include "tools/cli/plot_script.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tools/cli/error_message.h"

extern char** environ;

namespace orrery::cli {
namespace {

namespace fs = std::filesystem;

const char* kPackages =
    "Python 3 with matplotlib, numpy and h5py: install Debian's python3 python3-matplotlib python3-numpy "
    "python3-h5py (tools/install_deps.sh)";

// The last non-empty line of a file
std::string LastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

// The directory of the running executable ("" when unknown)
fs::path ExecutableDirectory() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

}  // namespace

std::string PythonInterpreter() {
  if (const char* python = std::getenv("ORRERY_PYTHON"); python && *python) return python;
  if (access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
  return "python3";
}

std::string PlotScriptPath(const std::string& script) {
  std::vector<fs::path> candidates;
  if (const char* dir = std::getenv("ORRERY_PLOT_DIR"); dir && *dir) candidates.emplace_back(dir);
  if (const fs::path exe = ExecutableDirectory(); !exe.empty()) candidates.push_back(exe / ".." / "share" / "orrery" / "plot");
#ifdef ORRERY_PLOT_SOURCE_DIR
  candidates.emplace_back(ORRERY_PLOT_SOURCE_DIR);
#endif
  std::string looked;
  for (const fs::path& dir : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(dir / script, ec)) return (dir / script).lexically_normal().string();
    looked += (looked.empty() ? "" : ", ") + dir.lexically_normal().string();
  }
  throw std::runtime_error("plotting script " + script + " not found (looked in " + looked + "; set ORRERY_PLOT_DIR)");
}

void RunPlotScript(const std::string& script, const std::vector<std::string>& args) {
  const std::string script_path = PlotScriptPath(script);
  const std::string python = PythonInterpreter();
  TemporaryFile errors(".log");

  // argv: python script args...
  std::vector<std::string> words = {python, script_path};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);

  // The script's output: nothing on stdout, error output to a file we read back
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, errors.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  pid_t pid = 0;
  const int spawned = python.find('/') == std::string::npos
                          ? posix_spawnp(&pid, python.c_str(), &actions, nullptr, argv.data(), environ)
                          : posix_spawn(&pid, python.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0)
    throw std::runtime_error("cannot run " + python + " (" + std::strerror(spawned) + "): plotting needs " + kPackages);

  // Wait, then report the script's own last error line
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("waiting for " + script + " failed: " + std::strerror(errno));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  // The scripts' own messages start with "orrery plot: error: " (tools/plot/orrery_plot.py)
  std::string last = OneLine(LastLine(errors.path()));
  const std::string prefix = "orrery plot: error: ";
  if (last.rfind(prefix, 0) == 0) last.erase(0, prefix.size());
  if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
    throw std::runtime_error("cannot run " + python + ": plotting needs " + std::string(kPackages));
  if (last.find("No module named") != std::string::npos && last.find("install") == std::string::npos)
    throw std::runtime_error(script + ": " + last + ": plotting needs " + kPackages);
  throw std::runtime_error(script + ": " + (last == "unknown error" ? "failed with status " + std::to_string(status) : last));
}

void CheckPngPath(const std::string& png_path) {
  const fs::path path(png_path);
  std::error_code ec;
  if (png_path.empty()) throw std::runtime_error("--png: no file name given");
  if (fs::is_directory(path, ec)) throw std::runtime_error(png_path + ": is a directory, not a PNG file name");
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(png_path + ": directory " + dir.string() + " does not exist");
}

TemporaryFile::TemporaryFile(const std::string& suffix) {
  std::string pattern = (fs::temp_directory_path() / ("orrery_XXXXXX" + suffix)).string();
  const int fd = mkstemps(pattern.data(), static_cast<int>(suffix.size()));
  if (fd < 0) throw std::runtime_error("cannot create a temporary file in " + fs::temp_directory_path().string() + ": " + std::strerror(errno));
  close(fd);
  path_ = pattern;
}

TemporaryFile::~TemporaryFile() {
  std::error_code ec;
  fs::remove(path_, ec);
}

}  // namespace orrery::cli
