#pragma once
// Runs the plotting scripts of tools/plot (Python 3 with Debian's python3-matplotlib,
// python3-numpy and python3-h5py) as separate programs. The C++ side computes; a script only
// draws what it is handed (a JSON file written by the command) or, for recorded series, reads the
// result file itself with h5py.
//
// Where things are found:
//   the interpreter  $ORRERY_PYTHON, else /usr/bin/python3 (Debian's, where its python3-*
//                    packages live), else python3 on the PATH
//   the scripts      $ORRERY_PLOT_DIR, else <orrery's directory>/../share/orrery/plot (an
//                    installed copy), else the source tree's tools/plot (compiled in)
//
// Failures throw std::runtime_error with one line: a missing interpreter or module names the
// Debian packages ("plotting needs Python 3 with matplotlib, numpy and h5py: install Debian's
// python3 python3-matplotlib python3-numpy python3-h5py (tools/install_deps.sh)"), a script
// error ends in the script's last line of error output.
//
// Usage:
//   RunPlotScript("spectrum_plot.py", {"--data", json_path, "--out", "spectrum.png"});
#include <string>
#include <vector>

namespace orrery::cli {

// The Python interpreter used (see above).
std::string PythonInterpreter();

// The full path of tools/plot/`script`. Throws when no directory above holds it.
std::string PlotScriptPath(const std::string& script);

// Runs `script` with `args`; returns when it has written its output. Throws (see above).
void RunPlotScript(const std::string& script, const std::vector<std::string>& args);

// Checks that `png_path` can be written: its directory exists and it is not a directory.
// Throws std::runtime_error naming the path.
void CheckPngPath(const std::string& png_path);

// A JSON file in the temporary directory, removed when this object goes. `path()` names it.
class TemporaryFile {
 public:
  explicit TemporaryFile(const std::string& suffix);
  ~TemporaryFile();
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace orrery::cli
