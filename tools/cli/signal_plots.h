#pragma once
// The plots of the signal commands (and of studies built on them), drawn by tools/plot's scripts
// through RunPlotScript (plot_script.h): the data computed here is written to a temporary JSON
// file and the script only draws it, so every number has one implementation.
//
//   PlotSpectrum      amplitude spectrum, peaks labelled, kinematic lines marked, zoom on the
//                     first mesh line with the sideband positions (spectrum_plot.py)
//   PlotOverlay       healthy and faulty spectra overlaid, mesh harmonics and their sidebands
//                     marked, the SERs in the zoom's title (overlay_plot.py)
//   PlotOctaveBands   one-third-octave levels as bars (octave_plot.py)
//   PlotTimeSignal    a recorded signal over time (time_signal_plot.py)
//   PlotHotSpotStress a flexible body's largest von Mises stress over time, read by the script
//                     from the result file (stress_plot.py)
// Each throws std::runtime_error with one line when the plot cannot be drawn (plot_script.h).
//
// Usage:
//   PlotSpectrum({.title = "...", .x_label = "frequency (Hz)", .y_label = "amplitude (m/s^2)"},
//                spectrum, peaks, lines, "spectrum.png");
#include <string>
#include <vector>

#include "tools/signal/amplitude_spectrum.h"
#include "tools/signal/kinematic_lines.h"
#include "tools/signal/peaks.h"
#include "tools/signal/signal_io.h"
#include "tools/signal/third_octave.h"

namespace orrery::cli {

struct PlotLabels {
  std::string title;
  std::string x_label;  // with the unit, e.g. "frequency (Hz)"
  std::string y_label;  // with the unit
};

// `lines` in the spectrum's x unit (Hz, or orders).
void PlotSpectrum(const PlotLabels& labels, const signal::Spectrum& spectrum, const std::vector<signal::Peak>& peaks,
                  const std::vector<signal::KinematicLine>& lines, const std::string& png);

// The SERs of both runs and their ratio (NaN: not available).
struct SerSummary {
  double healthy = 0, faulty = 0, ratio = 0;
  int harmonics = 3, sidebands = 6;  // as used
};

// Both spectra on the same bins.
void PlotOverlay(const PlotLabels& labels, const signal::Spectrum& healthy, const signal::Spectrum& faulty,
                 const signal::KinematicLine& mesh, const signal::KinematicLine& modulation, const SerSummary& ser,
                 const std::string& png);

void PlotOctaveBands(const PlotLabels& labels, const std::vector<signal::OctaveBand>& bands, const std::string& png);

void PlotTimeSignal(const PlotLabels& labels, const signal::RecordedSignal& signal, const std::string& png);

// Reads `dataset` (stress in Pa, optionally node id and x, y, z in m per row) and /time of `file`.
void PlotHotSpotStress(const std::string& file, const std::string& dataset, const std::string& png,
                       const std::string& title = "");

}  // namespace orrery::cli
