#pragma once
// `orrery spectrum OUT.h5 --signal PATH [--column C] [--window hann|flattop|rect] [--order MEMBER]
//                 [--t0 T] [--peaks N] [--json] [--png FILE]`
// The amplitude spectrum of a recorded signal with its peaks labelled by the scene's kinematic
// lines (tools/signal: AmplitudeSpectrum, FindPeaks, LabelPeaks).
//
// Steps: ReadSignal (column C of dataset PATH, from time T on); without --order, the first
// FastFftLength(n) samples (a length of prime factors 2, 3, 5; at most 6.3 % shorter from 1000
// samples on) are
// windowed and transformed; with --order MEMBER the signal is first resampled to the member's
// angle (/joints/MEMBER/q, or a dataset path; DefaultSamplesPerRevolution per revolution) and cut
// to whole revolutions, so the x axis is orders. Peaks (the largest N, 20 by default, above
// -60 dB) are interpolated and labelled from /kinematics/lines within one resolution (in orders,
// lines are divided by the member's mean rotation frequency over the record). A file without
// kinematic lines gives unlabelled peaks and one warning line on `err`.
//
// Text output: the record (file, signal, unit, samples, sample rate, resolution, window), then
// the peak table (frequency or order, amplitude, label).
// JSON (--json), exactly these keys:
//   {"file", "signal", "column", "unit", "window", "samples", "sample_rate_hz",
//    "resolution_hz" | "resolution_orders", "frequency_hz" | "order": [...], "amplitude": [...],
//    "peaks": [{"frequency_hz" | "order", "amplitude", "label"}],
//    with --order also "reference", "samples_per_revolution", "revolutions",
//    "mean_reference_frequency_hz"}
// Amplitudes are single-sided peak amplitudes in the signal's unit.
// --png FILE: the spectrum with its labelled peaks and the kinematic lines marked
// (tools/plot/spectrum_plot.py).
//
// Failures (missing file, dataset, column or reference, a record under 16 samples or one
// revolution, a plot that cannot be drawn) print one line "orrery: error: <file>: <path>: reason"
// and return kExitFailure.
#include <optional>
#include <ostream>
#include <string>

namespace orrery::cli {

struct SpectrumArgs {
  std::string path;             // OUT.h5
  std::string signal;           // --signal: dataset path
  std::string column;           // --column: index or name; "" for the first
  std::string window = "hann";  // --window
  std::string order_member;     // --order: "" for a time spectrum
  std::optional<double> t0;     // --t0 (s)
  int max_peaks = 20;           // --peaks
  bool json = false;
  std::string png;              // --png: "" for none
};

int SpectrumCommand(const SpectrumArgs& args, std::ostream& out, std::ostream& err);

}  // namespace orrery::cli
