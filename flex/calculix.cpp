#include "flex/calculix.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "flex/inp_file.h"

namespace orrery::flex {
namespace {

bool IsExecutable(const std::filesystem::path& p) {
  std::error_code ec;
  const std::filesystem::file_status s = std::filesystem::status(p, ec);
  return !ec && std::filesystem::is_regular_file(s) &&
         (s.permissions() & std::filesystem::perms::others_exec) != std::filesystem::perms::none;
}

std::string Tail(const std::filesystem::path& file, std::size_t max_chars) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  return s.size() > max_chars ? s.substr(s.size() - max_chars) : s;
}

}  // namespace

std::optional<std::filesystem::path> FindCalculix() {
  const char* path_env = std::getenv("PATH");
  if (!path_env) return std::nullopt;
  std::vector<std::filesystem::path> dirs;
  std::stringstream ss(path_env);
  for (std::string dir; std::getline(ss, dir, ':');)
    if (!dir.empty()) dirs.emplace_back(dir);
  for (const auto& d : dirs)
    if (IsExecutable(d / "ccx")) return d / "ccx";
  for (const auto& d : dirs) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(d, ec))
      if (entry.path().filename().string().rfind("ccx_", 0) == 0 && IsExecutable(entry.path())) return entry.path();
  }
  return std::nullopt;
}

std::vector<double> ReadCalculixEigenvalues(const std::filesystem::path& dat_file) {
  std::ifstream in(dat_file);
  if (!in) throw std::runtime_error(dat_file.string() + ": cannot open");
  std::string line;
  bool in_table = false;
  std::vector<double> w2;
  while (std::getline(in, line)) {
    if (!in_table) {
      in_table = line.find("E I G E N V A L U E   O U T P U T") != std::string::npos;
      continue;
    }
    // Rows "mode eigenvalue rad cycles imaginary"; the header lines do not parse
    std::istringstream row(line);
    int mode = 0;
    double lambda = 0, rad = 0, cycles = 0;
    if (row >> mode >> lambda >> rad >> cycles) {
      if (mode != static_cast<int>(w2.size()) + 1) break;
      w2.push_back(lambda);
    } else if (!w2.empty()) {
      break;  // end of the table
    }
  }
  if (w2.empty()) throw std::runtime_error(dat_file.string() + ": no eigenvalue output");
  return w2;
}

std::vector<double> RunCalculixFrequency(const std::filesystem::path& ccx, const FeMesh& mesh,
                                         const std::vector<std::string>& fixed_node_sets, int num_modes,
                                         const std::filesystem::path& work_dir) {
  std::filesystem::create_directories(work_dir);
  const std::string job = "orrery_modes";
  WriteInpFile(work_dir / (job + ".inp"), mesh,
               {.heading = "Orrery cross-check", .fixed_node_sets = fixed_node_sets, .num_frequencies = num_modes});
  std::filesystem::remove(work_dir / (job + ".dat"));
  const std::string command = "cd '" + work_dir.string() + "' && OMP_NUM_THREADS=1 '" + ccx.string() + "' -i " + job +
                              " > " + job + ".log 2>&1";
  const int status = std::system(command.c_str());
  const std::filesystem::path dat = work_dir / (job + ".dat");
  if (status != 0 || !std::filesystem::exists(dat))
    throw std::runtime_error("ccx failed (status " + std::to_string(status) + "): " + Tail(work_dir / (job + ".log"), 600));
  return ReadCalculixEigenvalues(dat);
}

}  // namespace orrery::flex
