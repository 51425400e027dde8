#pragma once
// Sampling of the sensors (sensor.h) as a data-acquisition system does it (docs/sensors.md):
//
//   integrator's dense output --(fixed internal rate f_i = M f_o)--> CalcSensorSignals
//     --> anti-alias low-pass (linear-phase FIR, anti_alias_filter.h) --> every M-th sample
//     --> /sensors/<name>/<quantity> at the output rate f_o = 1 / output interval
//
// The filter passes [0, passband_fraction f_N] (f_N = f_o / 2, the recorded Nyquist frequency)
// within its stated ripple and attenuates [f_N, f_i / 2] by at least stopband_attenuation_db, so
// nothing above f_N folds into the record by more than that: the whole recorded band is free of
// aliases to that level (the band from passband_fraction f_N to f_N is the filter's transition and
// rolls off). Its group delay is compensated: row k is the filter's output centred at
// t0 + k / f_o, so the rows line up with /time. Near both ends of a run, within the group delay,
// the signal is continued by odd reflection (anti_alias_filter.h). Point sampling
// (anti_alias = false) records the sensors at the output times themselves, as the body series do,
// and folds everything above f_N into the record.
//
// Internal samples come from Integrator::Interpolate at t0 + n / f_i, never beyond the end time.
// M (oversampling) by default: generalized-alpha with the output interval r steps (r a whole
// number): M = r for 4 <= r <= 20, else the largest divisor of r in [4, 20] (samples on steps,
// no interpolation), else 10; otherwise 10. The internal rate should resolve what the integrator
// resolves: content within f_o / 2 of a multiple of f_i folds at the internal sampling itself.
//
// Usage (Simulate does this when the model has sensors):
//   SensorSampler sampler(model, options.sensors, options.integrator, interval, end_time, out);
//   integrator->set_step_observer(&sampler);
//   integrator->Initialize(s0);  sampler.Start(integrator->state(), integrator->vdot());
//   for each output time t: integrator->AdvanceTo(t); (record /time) sampler.Release(t);
//   sampler.Finish(t_last);
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mbd/anti_alias_filter.h"
#include "mbd/data.h"
#include "mbd/integrator.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/state.h"

namespace orrery {

struct SensorSamplingOptions {
  bool anti_alias = true;           // false: point sampling at the output times (aliases fold)
  int oversampling = 0;             // M = internal rate / output rate; 0: automatic (above)
  double passband_fraction = 0.8;   // passband edge / recorded Nyquist frequency, in (0, 1)
  double stopband_attenuation_db = 100;  // from the recorded Nyquist frequency up, > 0
};

// M for these settings (the rule above; 1 for point sampling). Throws std::invalid_argument for
// an oversampling < 0 or a passband fraction outside (0, 1).
int ChooseOversampling(const SensorSamplingOptions& options, const IntegratorOptions& integrator,
                       double output_interval);

class SensorSampler final : public StepObserver {
 public:
  // Designs the filter, declares /sensors/<name>/<quantity> and writes the attributes (sensors,
  // filter). Keeps references to model and out. Throws std::invalid_argument for bad options.
  SensorSampler(const Model& model, const SensorSamplingOptions& options,
                const IntegratorOptions& integrator, double output_interval, double end_time,
                ResultFile& out);

  // The first sample, at the initial state (t0 = state.t).
  void Start(const State& state, const Eigen::VectorXd& vdot);
  // Samples the internal times in (last sample, t_end] from the integrator's dense output.
  void OnStep(Integrator& integrator, double t_begin, double t_end) override;
  // /time has its row at t: sensor rows up to t may be written (they are, once the samples the
  // filter needs beyond them exist).
  void Release(double t);
  // The run ends (or stopped) with its last /time row at t_last: writes every row up to it, the
  // ones within the group delay of the last sample with the signal reflected beyond it, and a
  // row at t_last itself when it is not on the output grid (filtered at the nearest internal
  // sample). Call once.
  void Finish(double t_last);

  int oversampling() const { return M_; }
  double internal_rate_hz() const { return M_ / interval_; }
  const FirLowPass& filter() const { return filter_; }
  long samples() const { return filter_rows_.samples(); }

 private:
  void Sample(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
              const Eigen::Ref<const Eigen::VectorXd>& v, const Eigen::Ref<const Eigen::VectorXd>& vdot);
  void ComputeReadyRows();   // grid rows whose samples have all arrived, into the row ring
  void WriteReleasedRows();  // computed rows up to the released one, to the file
  void WriteRow(const double* row);
  void DescribeInFile(const SensorSamplingOptions& options);

  const Model& model_;
  ResultFile& out_;
  Data data_;
  double interval_ = 0, end_time_ = 0, t0_ = 0, dt_ = 0;
  int M_ = 1;
  FirLowPass filter_;
  DecimatingFilter filter_rows_;
  std::vector<ResultFile::SeriesId> series_;  // per sensor
  long last_sample_index_ = -1;   // samples up to the end time: index of the last one allowed
  long next_sample_ = 0;          // index of the next internal sample
  // Grid rows k (input sample k M): computed into a ring of kRowRing rows, written once released.
  static constexpr long kRowRing = 64;
  Eigen::MatrixXd rows_;          // channels x kRowRing
  long next_written_ = 0, next_computed_ = 0, released_ = 0;  // rows [0, released_) releasable
  bool started_ = false, finished_ = false;
  long steps_ = 0;                // integrator steps observed (for integrator_steps_per_sample)
  Eigen::VectorXd q_, v_, vdot_;  // dense-output scratch
};

}  // namespace orrery
