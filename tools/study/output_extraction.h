#pragma once
// The outputs of a study (import/study_file.h, StudyOutput) extracted from one run's result file.
//
// Statistics of column c of a dataset over the rows whose time lies in [from, to] (any times; the
// rows of /time):
//   peak   max |x_i|            rms   sqrt((1/n) sum x_i^2)      mean  (1/n) sum x_i
//   min    min x_i              max   max x_i                    final x at the last row
//   max_stress  max of column 0 of /flexible_bodies/<body>/von_mises_max (Pa)
// A NaN in the window makes the statistic NaN (a run that diverged shows as NaN, not as a small
// number).
//
// Spectral outputs read the column as a uniformly sampled record from `from` to `to`
// (tools/signal/signal_io.h; at least 16 samples) and transform its first FastFftLength(n)
// samples (fft.h) with the chosen window (AmplitudeSpectrum, amplitude_spectrum.h):
//   amplitude  the amplitude of the line at f = harmonic f_line + sideband f_modulation (or
//              frequency_hz): the largest bin within the window's main lobe around f
//              (|k - f/Δf| <= B, MainLobeHalfWidthBins), interpolated to the sine behind it when
//              that bin is a local maximum (InterpolatePeak, Grandke 1983; exact for one sine),
//              else the bin's own amplitude (no line there, only leakage or noise)
//   sideband_energy_ratio  SidebandEnergyRatio(spectrum, f_mesh, f_modulation, {K, N}).ratio
// Lines are looked up by name in the result file's /kinematics/lines (kinematic_lines.h).
//
// Indicators (condition_indicators.h): rms, peak, crest_factor, kurtosis of the record, or of
// its time-synchronous average over the member `tsa` (time_synchronous_average.h; S samples per
// revolution, DefaultSamplesPerRevolution when not given); fm0, fm4, na4 of that average with
// the mesh order given, or f_mesh over the member's mean rotation frequency (a whole number
// within 0.05, as `orrery compare` takes it). NA4 is that of a single run (M = 1).
//
// Units: the dataset's "unit" attribute (its column's entry when it lists one per column) for
// the statistics, amplitude, rms and peak; "1" for ratios and the dimensionless indicators; "Pa"
// for max_stress.
//
// Usage:
//   ExtractedOutputs x = ExtractOutputs("runs/run_00003.h5", plan.study.outputs);
//   if (!x.error.empty()) ...   // x.values[i] is NaN for an output that failed
#include <string>
#include <vector>

#include "import/study_file.h"
#include "mbd/hdf5_reader.h"

namespace orrery::study {

// One output of an open result file; `unit` receives its unit. Throws std::runtime_error naming
// the file and dataset (a missing dataset or column, an empty window, a record too short, a line
// that is not in the file, ...).
double ExtractOutput(const Hdf5Reader& file, const StudyOutput& output, std::string* unit);

struct ExtractedOutputs {
  std::vector<double> values;      // one per output, NaN where extraction failed
  std::vector<std::string> units;  // one per output
  std::string error;               // "output 'name': reason" of the first failure, "" if none
};

// Every output of the result file at `path`; never throws (a file that cannot be opened fails
// every output).
ExtractedOutputs ExtractOutputs(const std::string& path, const std::vector<StudyOutput>& outputs);

}  // namespace orrery::study
