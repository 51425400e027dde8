#pragma once
// The folder a study writes, and how it survives being killed.
//
//   DIR/study.yaml           a copy of the study file
//   DIR/study.id             "study <hash>" of the study file, "scene <hash>" of the base scene
//   DIR/runs/run_00003.h5    the result file of run 3 (written by `orrery run`)
//   DIR/runs/run_00003.log   its standard output and error
//   DIR/runs/run_00003.done  its completion marker: the run's record (run_record.h)
//   DIR/index.h5, index.csv  parameters and outputs of every run (study_index.h)
//
// Resume: a run is finished when its marker holds a complete record. The marker is written after
// the run's process has exited (so its result file is closed) and its outputs are extracted: to
// a temporary file, flushed to disk (fsync), then renamed over the marker's name (an atomic step
// on POSIX file systems), and the folder is synced. A study killed at any moment leaves each run
// either finished (marker complete) or not (no marker, or only the temporary file); unfinished
// runs are run again from the start, their half-written result files overwritten.
//
// Identity: the hash is FNV-1a (64 bits) of the study file's bytes. A folder whose study.id names
// another hash holds a different study and is refused; so is a folder that exists, is not empty
// and has no study.id (it is not a study folder). A changed base scene is reported but not
// refused (runs done before and after the change then differ; the message says so).
//
// Usage:
//   StudyFolder folder = StudyFolder::Prepare("results/quick", "quick.yaml", text, scene_text, 6,
//   warn); if (!folder.ReadMarker(3)) RunIt(folder.ResultPath(3)); folder.WriteMarker(record,
//   parameters);
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "tools/study/run_record.h"

namespace orrery::study {

// FNV-1a, 64 bits, as 16 lower-case hexadecimal digits.
std::string HashText(std::string_view bytes);

class StudyFolder {
 public:
  // Creates the folder (and runs/) or opens it for the same study; writes study.yaml and study.id
  // when new. `runs` sets the width of the run numbers (at least 5 digits). Warnings (a changed
  // base scene) go to `warn`. Throws std::runtime_error "DIR: reason" when the folder holds
  // another study, is not a study folder, or cannot be written.
  static StudyFolder Prepare(const std::string& path, const std::string& study_file,
                             const std::string& study_text, const std::string& scene_text, int runs,
                             std::ostream& warn);
  // The same folder without checks or writes (MPI ranks other than 0, after rank 0 prepared it).
  static StudyFolder Open(const std::string& path, int runs);

  const std::string& path() const { return path_; }
  std::string ResultPath(int run) const;  // DIR/runs/run_00003.h5
  std::string LogPath(int run) const;     // DIR/runs/run_00003.log
  std::string MarkerPath(int run) const;  // DIR/runs/run_00003.done
  std::string IndexCsvPath() const;       // DIR/index.csv
  std::string IndexHdf5Path() const;      // DIR/index.h5

  // The record of a finished run: nullopt when the marker is missing or incomplete, or records
  // another run.
  std::optional<RunRecord> ReadMarker(int run) const;
  // Writes the marker atomically (see above). Throws std::runtime_error naming the file.
  void WriteMarker(const RunRecord& record, const std::vector<std::string>& parameters) const;

 private:
  StudyFolder(std::string path, int width) : path_(std::move(path)), width_(width) {}
  std::string RunStem(int run) const;
  std::string path_;
  int width_ = 5;
};

// Writes `text` to `path` atomically: PATH.tmp, fsync, rename, fsync of the folder. Throws
// std::runtime_error naming the file.
void WriteFileAtomically(const std::string& path, std::string_view text);

}  // namespace orrery::study
