#include "tools/study/study_folder.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace orrery::study {
namespace fs = std::filesystem;
namespace {

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The value of "key <value>" in an id file, "" when absent
std::string IdField(const std::string& id, const std::string& key) {
  std::istringstream in(id);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + " ", 0) == 0) return line.substr(key.size() + 1);
  return "";
}

int Digits(int n) {
  int d = 1;
  while (n >= 10) n /= 10, ++d;
  return d;
}

[[noreturn]] void FailErrno(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what + ": " + std::strerror(errno));
}

}  // namespace

std::string HashText(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(h));
  return buffer;
}

void WriteFileAtomically(const std::string& path, std::string_view text) {
  const std::string tmp = path + ".tmp";
  // Write and flush the temporary file
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) FailErrno(tmp, "cannot create");
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int saved = errno;
      ::close(fd);
      errno = saved;
      FailErrno(tmp, "cannot write");
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int saved = errno;
    ::close(fd);
    errno = saved;
    FailErrno(tmp, "cannot flush to disk");
  }
  if (::close(fd) != 0) FailErrno(tmp, "cannot close");
  // Rename over the final name, then make the rename durable
  if (::rename(tmp.c_str(), path.c_str()) != 0) FailErrno(path, "cannot rename " + tmp + " to it");
  const std::string dir =
      fs::path(path).parent_path().empty() ? "." : fs::path(path).parent_path().string();
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

StudyFolder StudyFolder::Prepare(const std::string& path, const std::string& study_file,
                                 const std::string& study_text, const std::string& scene_text,
                                 int runs, std::ostream& warn) {
  const fs::path dir(path);
  const fs::path id_path = dir / "study.id";
  const std::string study_hash = HashText(study_text), scene_hash = HashText(scene_text);
  std::error_code ec;
  if (fs::exists(id_path, ec)) {
    // The same study, or refused
    const std::string id = ReadFile(id_path);
    const std::string hash = IdField(id, "study");
    if (hash != study_hash)
      throw std::runtime_error(path + ": holds another study (study file hash " + hash + ", " +
                               study_file + " has " + study_hash +
                               "); choose another folder (-o DIR)");
    const std::string old_scene = IdField(id, "scene");
    if (old_scene != scene_hash)
      warn << "orrery: warning: " << path
           << ": the base scene changed since the study started (hash " << old_scene << ", now "
           << scene_hash << "); runs done before differ from runs done now\n";
  } else if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw std::runtime_error(path + ": exists and is not a folder");
    if (!fs::is_empty(dir, ec))
      throw std::runtime_error(
          path +
          ": not empty and not a study folder (no study.id); choose another folder (-o DIR)");
  }
  // Create the folder and its identity
  fs::create_directories(dir / "runs", ec);
  if (ec) throw std::runtime_error(path + ": cannot create the folder: " + ec.message());
  if (!fs::exists(id_path, ec)) {
    WriteFileAtomically((dir / "study.yaml").string(), study_text);
    WriteFileAtomically(id_path.string(), "study " + study_hash + "\nscene " + scene_hash + "\n");
  }
  return Open(path, runs);
}

StudyFolder StudyFolder::Open(const std::string& path, int runs) {
  return StudyFolder(path, std::max(5, Digits(std::max(0, runs - 1))));
}

std::string StudyFolder::RunStem(int run) const {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "run_%0*d", width_, run);
  return (fs::path(path_) / "runs" / buffer).string();
}

std::string StudyFolder::ResultPath(int run) const { return RunStem(run) + ".h5"; }
std::string StudyFolder::LogPath(int run) const { return RunStem(run) + ".log"; }
std::string StudyFolder::MarkerPath(int run) const { return RunStem(run) + ".done"; }
std::string StudyFolder::IndexCsvPath() const { return (fs::path(path_) / "index.csv").string(); }
std::string StudyFolder::IndexHdf5Path() const { return (fs::path(path_) / "index.h5").string(); }

std::optional<RunRecord> StudyFolder::ReadMarker(int run) const {
  std::error_code ec;
  const std::string path = MarkerPath(run);
  if (!fs::exists(path, ec)) return std::nullopt;
  try {
    RunRecord r = DecodeRunRecord(ReadFile(path));
    if (r.run != run) return std::nullopt;
    return r;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void StudyFolder::WriteMarker(const RunRecord& record,
                              const std::vector<std::string>& parameters) const {
  WriteFileAtomically(MarkerPath(record.run), EncodeRunRecord(record, parameters));
}

}  // namespace orrery::study
