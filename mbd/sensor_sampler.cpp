#include "mbd/sensor_sampler.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "mbd/sensor_signals.h"

namespace orrery {
namespace {

// The internal grid's tolerance: a time within this fraction of an internal period of a grid
// point is on it (output times are computed as t0 + k interval, internal ones as t0 + n dt).
constexpr double kGridTolerance = 1e-6;

FirLowPass DesignFilter(const SensorSamplingOptions& o, int M) {
  if (!o.anti_alias || M == 1) {
    FirLowPass identity;
    identity.taps = {1.0};
    return identity;
  }
  // Edges in cycles per internal sample: the recorded Nyquist frequency is 1 / (2 M).
  const double nyquist = 0.5 / M;
  return DesignKaiserLowPass(o.passband_fraction * nyquist, nyquist, o.stopband_attenuation_db);
}

std::string Vec3Text(const Vec3& p) {
  std::ostringstream s;
  s.precision(17);
  s << p.x() << ", " << p.y() << ", " << p.z();
  return s.str();
}

}  // namespace

int ChooseOversampling(const SensorSamplingOptions& o, const IntegratorOptions& integrator,
                       double output_interval) {
  if (o.oversampling < 0)
    throw std::invalid_argument("sensor sampling: oversampling must be >= 0 (0: automatic), got " +
                                std::to_string(o.oversampling));
  if (!(o.passband_fraction > 0 && o.passband_fraction < 1))
    throw std::invalid_argument("sensor sampling: passband fraction must be in (0, 1), got " +
                                std::to_string(o.passband_fraction));
  if (!(o.stopband_attenuation_db > 0) || !std::isfinite(o.stopband_attenuation_db))
    throw std::invalid_argument("sensor sampling: stopband attenuation must be > 0 dB");
  if (!o.anti_alias) return 1;
  if (o.oversampling > 0) return o.oversampling;
  // Generalized-alpha with a whole number r of steps per output: samples on steps.
  if (integrator.kind == IntegratorKind::kGeneralizedAlpha && integrator.step > 0) {
    const double r = output_interval / integrator.step;
    const long n = std::lround(r);
    if (n >= 4 && std::abs(r - n) <= 1e-6 * r) {
      if (n <= 20) return static_cast<int>(n);
      for (int d = 20; d >= 4; --d)
        if (n % d == 0) return d;
    }
  }
  return 10;
}

SensorSampler::SensorSampler(const Model& model, const SensorSamplingOptions& options,
                             const IntegratorOptions& integrator, double output_interval,
                             double end_time, ResultFile& out)
    : model_(model),
      out_(out),
      data_(model),
      interval_(output_interval),
      end_time_(end_time),
      M_(ChooseOversampling(options, integrator, output_interval)),
      filter_(DesignFilter(options, M_)),
      // History: the filter's window, the rows the ring may hold ahead, and a margin.
      filter_rows_(filter_.taps, std::max(1, model.n_sensor_channels),
                   static_cast<long>(filter_.taps.size()) + (kRowRing + 2) * M_) {
  if (!(output_interval > 0)) throw std::invalid_argument("sensor sampling: output interval must be > 0");
  dt_ = interval_ / M_;
  rows_.setZero(std::max(1, model.n_sensor_channels), kRowRing);
  q_.setZero(model.nq);
  v_.setZero(model.nv);
  vdot_.setZero(model.nv);
  for (const Sensor& s : model.sensors)
    series_.push_back(out.AddSeries("/sensors/" + s.spec.name + "/" + s.quantity, s.channels, s.unit,
                                    s.columns));
  DescribeInFile(options);
}

void SensorSampler::DescribeInFile(const SensorSamplingOptions& options) {
  const std::string g = "/sensors";
  const double fo = 1 / interval_, fn = 0.5 * fo, fi = M_ * fo;
  const bool filtered = filter_.taps.size() > 1;
  out_.SetAttribute(g, "sampling", std::string(filtered ? "anti-alias low-pass at the internal rate, "
                                                          "then every M-th sample (decimation)"
                                                        : "point sampling at the output times (no "
                                                          "anti-alias filter: content above the "
                                                          "Nyquist frequency folds into the record)"));
  out_.SetAttribute(g, "output_rate_hz", fo);
  out_.SetAttribute(g, "nyquist_hz", fn);
  out_.SetAttribute(g, "internal_rate_hz", fi);
  out_.SetAttribute(g, "decimation", std::int64_t(M_));
  if (filtered) {
    out_.SetAttribute(g, "filter_type", std::string("linear-phase FIR low-pass, window method with a "
                                                    "Kaiser window, group delay compensated"));
    out_.SetAttribute(g, "filter_order", std::int64_t(filter_.order()));
    out_.SetAttribute(g, "kaiser_beta", filter_.kaiser_beta);
    out_.SetAttribute(g, "passband_edge_hz", filter_.passband_edge * fi);
    out_.SetAttribute(g, "passband_edge_vs_nyquist", options.passband_fraction);
    out_.SetAttribute(g, "cutoff_hz", 0.5 * (filter_.passband_edge + filter_.stopband_edge) * fi);
    out_.SetAttribute(g, "cutoff_vs_nyquist", 0.5 * (options.passband_fraction + 1));
    out_.SetAttribute(g, "stopband_edge_hz", filter_.stopband_edge * fi);
    out_.SetAttribute(g, "stopband_edge_vs_nyquist", 1.0);
    out_.SetAttribute(g, "stopband_attenuation_db", filter_.design_attenuation_db);
    out_.SetAttribute(g, "measured_stopband_attenuation_db", filter_.stopband_attenuation_db);
    out_.SetAttribute(g, "passband_ripple_db", filter_.passband_ripple_db);
    out_.SetAttribute(g, "group_delay_s", filter_.delay_samples() * dt_);
    out_.SetAttribute(g, "alignment", std::string("group delay compensated: row k is the filter's "
                                                  "output centred at the time of /time row k"));
    out_.SetAttribute(g, "edges", std::string("the signal is continued by odd reflection "
                                              "(2 x_end - x_mirror) beyond the first and last "
                                              "samples: rows within group_delay_s of either end "
                                              "are approximate"));
    out_.WriteVector(g + "/filter_taps", filter_.taps, "1");
  }
  // Each sensor: what it measures and where.
  for (const Sensor& s : model_.sensors) {
    const SensorSpec& spec = s.spec;
    const std::string sg = g + "/" + spec.name;
    out_.SetAttribute(sg, "kind", std::string(SensorKindName(spec.kind)));
    out_.SetAttribute(sg, "quantity", s.quantity);
    switch (spec.kind) {
      case SensorKind::kEncoder:
      case SensorKind::kTachometer:
        out_.SetAttribute(sg, "joint", model_.joints[spec.joint].spec.name);
        out_.SetAttribute(sg, "coordinate", std::int64_t(spec.coordinate));
        break;
      case SensorKind::kGearMesh:
        out_.SetAttribute(sg, "gear_mesh", model_.gear_meshes[spec.gear_mesh].spec.name);
        break;
      case SensorKind::kElementOutput:
        out_.SetAttribute(sg, "element", model_.external_forces[spec.element]->name());
        out_.SetAttribute(sg, "output", spec.output);
        break;
      default: {
        const Frame& f = model_.frames[spec.frame];
        out_.SetAttribute(sg, "body", model_.bodies[f.body].name);
        out_.SetAttribute(sg, "frame", f.name);
        out_.SetAttribute(sg, "position_in_body_m", Vec3Text(f.X_BF * spec.X_FS.p));
        if (f.node >= 0) {
          const auto& modes = *model_.flexible_bodies[model_.bodies[f.body].flexible].modes;
          out_.SetAttribute(sg, "node", std::int64_t(modes.nodes[f.node].id));
        }
        out_.SetAttribute(sg, "measured_in", spec.measured_in == kSensorAxes
                                                 ? std::string("sensor (the frame's own axes)")
                                                 : model_.frames[spec.measured_in].name);
        std::string axes;
        for (const std::string& c : s.columns) axes += (axes.empty() ? "" : ",") + c;
        out_.SetAttribute(sg, "axes", axes);
        if (spec.kind == SensorKind::kAccelerometer)
          out_.SetAttribute(sg, "include_gravity", std::int64_t(spec.include_gravity ? 1 : 0));
      }
    }
  }
}

void SensorSampler::Start(const State& state, const Eigen::VectorXd& vdot) {
  t0_ = state.t;
  last_sample_index_ = static_cast<long>(std::floor((end_time_ - t0_) / dt_ + kGridTolerance));
  started_ = true;
  Sample(t0_, state.q, state.v, vdot);
}

void SensorSampler::OnStep(Integrator& integrator, double t_begin, double t_end) {
  if (!started_ || finished_) return;
  ++steps_;
  while (next_sample_ <= last_sample_index_) {
    const double t = t0_ + next_sample_ * dt_;
    if (t > t_end + kGridTolerance * dt_) break;
    integrator.Interpolate(std::clamp(t, t_begin, t_end), q_, v_, vdot_);
    Sample(t, q_, v_, vdot_);
  }
}

void SensorSampler::Sample(double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& v,
                           const Eigen::Ref<const Eigen::VectorXd>& vdot) {
  CalcSensorSignals(model_, t, q, v, vdot, data_);
  filter_rows_.Push(data_.sensor_values.data());
  ++next_sample_;
  ComputeReadyRows();
  WriteReleasedRows();
}

void SensorSampler::ComputeReadyRows() {
  while (filter_rows_.Ready(next_computed_ * M_)) {
    // A full ring (the integrator ran more than kRowRing rows ahead of /time): write the oldest.
    if (next_computed_ - next_written_ == kRowRing) {
      WriteRow(rows_.col(next_written_ % kRowRing).data());
      ++next_written_;
    }
    filter_rows_.Output(next_computed_ * M_, rows_.col(next_computed_ % kRowRing).data());
    ++next_computed_;
  }
}

void SensorSampler::WriteReleasedRows() {
  while (next_written_ < next_computed_ && next_written_ < released_) {
    WriteRow(rows_.col(next_written_ % kRowRing).data());
    ++next_written_;
  }
}

void SensorSampler::WriteRow(const double* row) {
  for (size_t i = 0; i < series_.size(); ++i)
    out_.Append(series_[i], row + model_.sensors[i].channel_start);
}

void SensorSampler::Release(double t) {
  const long k = static_cast<long>(std::floor((t - t0_) / interval_ + kGridTolerance));
  released_ = std::max(released_, k + 1);
  WriteReleasedRows();
}

void SensorSampler::Finish(double t_last) {
  if (!started_ || finished_) return;
  finished_ = true;
  // Steps per internal sample above 1: the integrator resolved faster motion than the internal
  // rate samples, which could fold at the internal sampling (sensor_sampler.h).
  out_.SetAttribute("/sensors", "integrator_steps_per_sample",
                    double(steps_) / double(std::max(1L, filter_rows_.samples())));
  Release(t_last);
  // Rows up to t_last whose windows reach beyond the last sample: reflected there.
  const long k_last = released_ - 1;
  for (; next_written_ <= k_last; ++next_written_) {
    if (next_written_ < next_computed_) {
      WriteRow(rows_.col(next_written_ % kRowRing).data());
      continue;
    }
    const long n = std::min(next_written_ * M_, filter_rows_.samples() - 1);
    filter_rows_.Output(n, rows_.col(0).data());
    WriteRow(rows_.col(0).data());
  }
  next_computed_ = std::max(next_computed_, next_written_);
  // A last row off the output grid (the end time): at the nearest internal sample.
  const double k_exact = (t_last - t0_) / interval_;
  if (std::abs(k_exact - std::round(k_exact)) * M_ > kGridTolerance) {
    const long n = std::min(std::lround((t_last - t0_) / dt_), filter_rows_.samples() - 1);
    filter_rows_.Output(n, rows_.col(0).data());
    WriteRow(rows_.col(0).data());
  }
}

}  // namespace orrery
