// The sensor chain through Simulate (mbd/sensor_sampler.cpp): internal samples from the
// integrators' dense output, the anti-alias filter, decimation, the result file's layout.
//
// Oracles, none written in the project: closed-form motions (a body turning at a ramped speed:
// centripetal and tangential acceleration; a flexible body ringing in one mode; two prismatic
// stages shaken by sines; a shaft at a sine-modulated speed), and the folding rule of sampling
// (a tone at f_2 sampled at f_o appears at |f_2 - round(f_2 / f_o) f_o|). The filtered records
// must hold the in-band motion within the filter's stated passband ripple plus the integration
// error (IDA at rtol 1e-10: relative errors of order 1e-9), the point-sampled ones within the
// integration error, and a tone above the recorded Nyquist frequency must not appear at its alias
// by more than the stated stopband attenuation, while point sampling shows it there in full.
// Rows within the filter's group delay of either end are left out where the filter is checked
// (there the signal is continued by reflection; sensor_sampler.h).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <numbers>
#include <string>

#include <Eigen/Dense>

#include "mbd/hdf5_reader.h"
#include "mbd/data.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/simulation.h"
#include "tests/common/plain_test_element.h"

namespace orrery {
namespace {

constexpr double kPi = std::numbers::pi;

JointSpec Joint(const std::string& name, JointType type, BodyIndex parent, BodyIndex child,
                const Vec3& axis = Vec3::UnitZ()) {
  JointSpec j;
  j.name = name, j.type = type, j.parent = parent, j.child = child, j.axis = axis;
  return j;
}

IntegratorOptions Ida(double rtol = 1e-10) {
  IntegratorOptions o;
  o.kind = IntegratorKind::kIda;
  o.rtol = rtol;
  o.atol = 1e-12;
  return o;
}

// Runs the model into a temporary file and keeps it open for reading.
struct Record {
  std::string path;
  std::unique_ptr<Hdf5Reader> file;
  Eigen::VectorXd time;
  Eigen::MatrixXd Read(const std::string& p) const { return file->ReadMatrix(p); }
  double Attribute(const std::string& p, const std::string& key) const {
    return std::stod(file->ReadAttributeText(p, key));
  }
  ~Record() {
    file.reset();
    std::filesystem::remove(path);
  }
};
std::unique_ptr<Record> RunModel(const Model& model, SimulationOptions o, const std::string& tag) {
  auto r = std::make_unique<Record>();
  r->path = ::testing::TempDir() + "orrery_sensors_" + tag + "_" + std::to_string(::getpid()) + ".h5";
  {
    ResultFile out = ResultFile::Create(r->path);
    Simulate(model, o, &out);
  }
  r->file = std::make_unique<Hdf5Reader>(r->path);
  r->time = r->file->ReadMatrix("/time").col(0);
  return r;
}

// Rows at least the group delay (plus one row) away from both ends of the record.
std::vector<int> InteriorRows(const Record& r) {
  const double delay = r.file->Exists("/sensors/filter_taps") ? r.Attribute("/sensors", "group_delay_s") : 0;
  const double T = r.time(1) - r.time(0), end = r.time(r.time.size() - 1);
  std::vector<int> rows;
  for (int i = 0; i < r.time.size(); ++i)
    if (r.time(i) >= r.time(0) + delay + T && r.time(i) <= end - delay - T) rows.push_back(i);
  return rows;
}

// The filter's passband deviation as a fraction: 10^(ripple_db / 20) - 1.
double Ripple(const Record& r) {
  return std::pow(10.0, r.Attribute("/sensors", "passband_ripple_db") / 20) - 1;
}

// Largest |recorded - expected| over the rows, with `expected(t)` a row of the sensor's width.
double WorstError(const Record& r, const std::string& series, const std::vector<int>& rows,
                  const std::function<Eigen::VectorXd(double)>& expected) {
  const Eigen::MatrixXd x = r.Read(series);
  EXPECT_EQ(x.rows(), r.time.size()) << series;
  double worst = 0;
  for (int i : rows) worst = std::max(worst, (x.row(i).transpose() - expected(r.time(i))).lpNorm<Eigen::Infinity>());
  return worst;
}

// Least-squares amplitudes of sines at `freqs` (Hz) in column `c` of a series over rows.
std::vector<double> SineAmplitudes(const Record& r, const std::string& series, const std::vector<int>& rows,
                                   const std::vector<double>& freqs) {
  const Eigen::MatrixXd x = r.Read(series);
  const int n = static_cast<int>(rows.size()), m = static_cast<int>(freqs.size());
  Eigen::MatrixXd A(n, 2 * m);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const double t = r.time(rows[i]);
    for (int k = 0; k < m; ++k) {
      A(i, 2 * k) = std::cos(2 * kPi * freqs[k] * t);
      A(i, 2 * k + 1) = std::sin(2 * kPi * freqs[k] * t);
    }
    b(i) = x(rows[i], 0);
  }
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  std::vector<double> amp;
  for (int k = 0; k < m; ++k) amp.push_back(std::hypot(c(2 * k), c(2 * k + 1)));
  return amp;
}

// ---------------------------------------------------------------------------------------------
// A disk turning about z at omega(t) = 5 + 10 t rad/s; accelerometers at r = 0.1 m.

std::shared_ptr<const Model> TurningDisk() {
  ModelBuilder b;
  const BodyIndex disk = b.AddBody("disk", 2.0, Vec3::Zero(), Vec3(0.01, 0.01, 0.02).asDiagonal());
  const JointIndex j = b.AddJoint(Joint("spin", JointType::kRevolute, kWorldBody, disk));
  b.SetJointVelocity(j, Eigen::VectorXd::Constant(1, 5.0));
  b.AddDriver({"motor", j, 0, DriverSpec::Mode::kSpeed, TimeFunction::Ramp(0, 1, 5, 15)});
  const FrameIndex tip = b.AddFrame("tip", disk, Transform::Translation(Vec3(0.1, 0, 0.02)));
  b.AddSensor({.name = "acc_body", .kind = SensorKind::kAccelerometer, .frame = tip});
  b.AddSensor({.name = "acc_world", .kind = SensorKind::kAccelerometer, .frame = tip,
               .measured_in = kWorldFrame, .axes = {0, 1}});
  b.AddSensor({.name = "gyro", .kind = SensorKind::kGyroscope, .frame = tip, .axes = {2}});
  return std::move(b).Finalize();
}

// Body axes: centripetal -omega^2 r along x, tangential alpha r along y; world axes: turned by
// theta = 5 t + 5 t^2.
Eigen::VectorXd DiskBody(double t) {
  const double w = 5 + 10 * t;
  return Eigen::Vector3d(-w * w * 0.1, 10 * 0.1, 0);
}
Eigen::VectorXd DiskWorld(double t) {
  const double th = 5 * t + 5 * t * t;
  const Eigen::Vector3d a = DiskBody(t);
  return Eigen::Vector2d(std::cos(th) * a.x() - std::sin(th) * a.y(), std::sin(th) * a.x() + std::cos(th) * a.y());
}

TEST(SensorSampler, AccelerometerOnATurningBodyInBodyAndWorldAxes) {
  const std::shared_ptr<const Model> model = TurningDisk();
  const double a_max = 15 * 15 * 0.1;  // m/s^2
  for (const bool filtered : {false, true}) {
    SimulationOptions o;
    o.end_time = 1.0;
    o.output_interval = 1e-3;
    o.integrator = Ida();
    o.sensors.anti_alias = filtered;
    const auto r = RunModel(*model, o, filtered ? "disk_filtered" : "disk_point");
    SCOPED_TRACE(filtered ? "filtered" : "point sampled");
    const std::vector<int> rows = InteriorRows(*r);
    ASSERT_GT(rows.size(), 900u);
    // Integration error (relative 1e-8: IDA at rtol 1e-10 over 1e3 outputs), plus the
    // passband ripple for the filtered record.
    const double tol = a_max * (1e-8 + (filtered ? Ripple(*r) : 0));
    EXPECT_LE(WorstError(*r, "/sensors/acc_body/acceleration", rows, DiskBody), tol);
    EXPECT_LE(WorstError(*r, "/sensors/acc_world/acceleration", rows, DiskWorld), tol);
    EXPECT_LE(WorstError(*r, "/sensors/gyro/angular_velocity", rows,
                         [](double t) { return Eigen::VectorXd::Constant(1, 5 + 10 * t); }),
              15 * (1e-8 + (filtered ? Ripple(*r) : 0)));
  }
}

TEST(SensorSampler, GeneralizedAlphaOnStepsAndInterpolated) {
  // Samples on the steps (M = 10 steps per output) and between them (M = 16, cubic Hermite):
  // v is linear and q quadratic in t here, which the interpolation reproduces exactly, so both
  // records hold the closed form within the integrator's own error.
  const std::shared_ptr<const Model> model = TurningDisk();
  for (const int M : {0, 16}) {
    SimulationOptions o;
    o.end_time = 0.5;
    o.output_interval = 1e-3;
    o.integrator.kind = IntegratorKind::kGeneralizedAlpha;
    o.integrator.step = 1e-4;
    o.sensors.oversampling = M;
    const auto r = RunModel(*model, o, "disk_ga" + std::to_string(M));
    EXPECT_EQ(r->Attribute("/sensors", "decimation"), M == 0 ? 10 : 16);
    const std::vector<int> rows = InteriorRows(*r);
    const double tol = 15 * 15 * 0.1 * (1e-8 + Ripple(*r));
    EXPECT_LE(WorstError(*r, "/sensors/acc_body/acceleration", rows, DiskBody), tol) << "M = " << M;
    EXPECT_LE(WorstError(*r, "/sensors/acc_world/acceleration", rows, DiskWorld), tol) << "M = " << M;
  }
}

// ---------------------------------------------------------------------------------------------
// A carriage shaken at f1 = 100 Hz carries a shaker at f2 = 1130 Hz (both prismatic along x,
// position drivers): a = -(2 pi f1)^2 A1 sin(2 pi f1 t) - (2 pi f2)^2 A2 sin(2 pi f2 t). Recorded
// at 1 kHz (Nyquist 500 Hz), the 1130 Hz tone folds to 130 Hz.

TEST(SensorSampler, AToneAboveNyquistDoesNotFoldIntoTheRecord) {
  const double f1 = 100, A1 = 1e-3, f2 = 1130, A2 = 1e-5;
  const double a1 = std::pow(2 * kPi * f1, 2) * A1, a2 = std::pow(2 * kPi * f2, 2) * A2;
  ModelBuilder b;
  const Mat3 I = Mat3::Identity() * 1e-3;
  const BodyIndex carriage = b.AddBody("carriage", 2.0, Vec3::Zero(), I);
  const BodyIndex shaker = b.AddBody("shaker", 0.5, Vec3::Zero(), I);
  const JointIndex j1 = b.AddJoint(Joint("rail", JointType::kPrismatic, kWorldBody, carriage, Vec3::UnitX()));
  const JointIndex j2 = b.AddJoint(Joint("stroke", JointType::kPrismatic, carriage, shaker, Vec3::UnitX()));
  b.SetJointVelocity(j1, Eigen::VectorXd::Constant(1, 2 * kPi * f1 * A1));
  b.SetJointVelocity(j2, Eigen::VectorXd::Constant(1, 2 * kPi * f2 * A2));
  b.AddDriver({"low", j1, 0, DriverSpec::Mode::kPosition, TimeFunction::Sine(A1, f1, 0, 0)});
  b.AddDriver({"high", j2, 0, DriverSpec::Mode::kPosition, TimeFunction::Sine(A2, f2, 0, 0)});
  b.AddSensor({.name = "acc", .kind = SensorKind::kAccelerometer, .frame = b.body_frame(shaker),
               .measured_in = kWorldFrame, .axes = {0}});
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  const double alias = std::abs(f2 - std::round(f2 / 1000) * 1000);
  ASSERT_EQ(alias, 130);
  std::vector<double> point, filtered;
  double stated_db = 0;
  for (const bool anti_alias : {false, true}) {
    SimulationOptions o;
    o.end_time = 1.0;
    o.output_interval = 1e-3;
    o.integrator = Ida(1e-9);
    o.sensors.anti_alias = anti_alias;
    const auto r = RunModel(*model, o, anti_alias ? "alias_filtered" : "alias_point");
    // 0.1 .. 0.9 s: whole numbers of periods of both 100 and 130 Hz (and clear of the edges).
    std::vector<int> rows;
    for (int i = 0; i < r->time.size(); ++i)
      if (r->time(i) >= 0.1 - 1e-9 && r->time(i) < 0.9 - 1e-9) rows.push_back(i);
    (anti_alias ? filtered : point) = SineAmplitudes(*r, "/sensors/acc/acceleration", rows, {f1, alias});
    if (anti_alias) stated_db = r->Attribute("/sensors", "stopband_attenuation_db");
  }
  // Point sampling: the 1130 Hz tone sits at 130 Hz in full (integration error 1e-6 relative).
  EXPECT_NEAR(point[0], a1, 1e-6 * a1);
  EXPECT_NEAR(point[1], a2, 1e-6 * a2);
  // Anti-aliased: at 130 Hz at most a2 10^(-A/20); 100 Hz passes.
  EXPECT_EQ(stated_db, 100);
  EXPECT_LE(filtered[1], a2 * std::pow(10.0, -stated_db / 20));
  EXPECT_NEAR(filtered[0], a1, 1e-4 * a1);
  std::printf("  a2 = %.1f m/s^2 at 1130 Hz; at its alias 130 Hz: point sampled %.1f, filtered %.3g "
              "(%.1f dB below)\n", a2, point[1], filtered[1], 20 * std::log10(a2 / filtered[1]));
}

// ---------------------------------------------------------------------------------------------
// A flexible body held by a fixed joint, ringing in one mode: q_f = (V / w) sin(w t).

TEST(SensorSampler, NodeSensorOfAFlexibleBodyInOneMode) {
  auto modes = std::make_shared<FlexibleBodyModes>();
  modes->nf = 1;
  const Vec3 phi(0.2, 1.0, -0.3), x_node(0.3, 0.05, 0);
  const double m_node = 0.5, m_core = 3.0;
  modes->mass = m_core + m_node;
  modes->I1 = m_node * x_node;
  modes->I3 = Vec3(0.05, 0.05, 0.05).asDiagonal();
  modes->I3 += m_node * x_node * x_node.transpose();
  modes->I2 = m_node * phi;
  modes->I4 = {m_node * x_node * phi.transpose()};
  modes->I5 = {m_node * phi * phi.transpose()};
  const double f = 60, M_ff = m_node * phi.squaredNorm(), w = 2 * kPi * f;
  modes->stiffness = Eigen::MatrixXd::Constant(1, 1, w * w * M_ff);
  FlexibleBodyModes::Node node;
  node.id = 7;
  node.position = x_node;
  node.translation_shapes = phi;
  modes->nodes = {node};
  ModelBuilder b;
  const BodyIndex body = b.AddFlexibleBody("beam", modes);
  b.AddJoint(Joint("mount", JointType::kFixed, kWorldBody, body));
  const double V = 0.02;
  b.SetModalCoordinates(body, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Constant(1, V));
  const FrameIndex tip = b.AddNodeFrame("tip", body, 0, Transform::Translation(x_node));
  b.AddSensor({.name = "acc", .kind = SensorKind::kAccelerometer, .frame = tip, .measured_in = kWorldFrame});
  b.AddSensor({.name = "deflection", .kind = SensorKind::kDisplacement, .frame = tip,
               .measured_in = b.body_frame(body)});
  const std::shared_ptr<const Model> model = std::move(b).Finalize();
  SimulationOptions o;
  o.end_time = 0.3;
  o.output_interval = 1e-3;
  o.integrator = Ida();
  const auto r = RunModel(*model, o, "flex");
  const std::vector<int> rows = InteriorRows(*r);
  const double amp_a = V * w * phi.norm(), amp_d = V / w * phi.norm();
  EXPECT_LE(WorstError(*r, "/sensors/acc/acceleration", rows,
                       [&](double t) { return Eigen::VectorXd(-V * w * std::sin(w * t) * phi); }),
            amp_a * (1e-7 + Ripple(*r)));
  EXPECT_LE(WorstError(*r, "/sensors/deflection/displacement", rows,
                       [&](double t) { return Eigen::VectorXd(V / w * std::sin(w * t) * phi); }),
            amp_d * (1e-7 + Ripple(*r)));
  EXPECT_EQ(r->file->ReadAttributeText("/sensors/acc", "node"), "7");
}

// ---------------------------------------------------------------------------------------------
// Encoder and tachometer on a shaft at omega = 10 + 2 sin(2 pi 5 t).

std::shared_ptr<const Model> Shaft() {
  ModelBuilder b;
  const BodyIndex shaft = b.AddBody("shaft", 1.0, Vec3::Zero(), Vec3(0.01, 0.01, 0.02).asDiagonal());
  const JointIndex j = b.AddJoint(Joint("bearing", JointType::kRevolute, kWorldBody, shaft));
  b.SetJointVelocity(j, Eigen::VectorXd::Constant(1, 10.0));
  b.AddDriver({"motor", j, 0, DriverSpec::Mode::kSpeed, TimeFunction::Sine(2, 5, 0, 10)});
  b.AddSensor({.name = "encoder", .kind = SensorKind::kEncoder, .joint = j});
  b.AddSensor({.name = "tacho", .kind = SensorKind::kTachometer, .joint = j});
  return std::move(b).Finalize();
}

TEST(SensorSampler, EncoderAndTachometerReadTheJoint) {
  const std::shared_ptr<const Model> model = Shaft();
  const double w5 = 2 * kPi * 5;
  auto angle = [&](double t) { return Eigen::VectorXd::Constant(1, 10 * t + 2 / w5 * (1 - std::cos(w5 * t))); };
  auto speed = [&](double t) { return Eigen::VectorXd::Constant(1, 10 + 2 * std::sin(w5 * t)); };
  for (const bool anti_alias : {false, true}) {
    SimulationOptions o;
    o.end_time = 1.0;
    o.output_interval = 1e-3;
    o.integrator = Ida();
    o.sensors.anti_alias = anti_alias;
    const auto r = RunModel(*model, o, anti_alias ? "shaft_filtered" : "shaft_point");
    const std::vector<int> rows = InteriorRows(*r);
    // The ramp 10 t passes the filter exactly (linear phase, unit DC gain); the sine of amplitude
    // 2 / w5 within the ripple.
    const double ripple = anti_alias ? Ripple(*r) : 0;
    EXPECT_LE(WorstError(*r, "/sensors/encoder/angle", rows, angle), 10 * 1e-8 + 2 / w5 * ripple);
    EXPECT_LE(WorstError(*r, "/sensors/tacho/angular_velocity", rows, speed), 12 * 1e-8 + 2 * ripple);
    if (!anti_alias) {
      // Point sampled: the joint's own record, row for row.
      const Eigen::MatrixXd q = r->Read("/joints/bearing/q"), e = r->Read("/sensors/encoder/angle");
      ASSERT_EQ(q.rows(), e.rows());
      EXPECT_LE((q - e).lpNorm<Eigen::Infinity>(), 1e-12);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Layout: one row per /time row (an end time off the output grid included), the attributes.

TEST(SensorSampler, ResultFileLayoutAndAttributes) {
  const std::shared_ptr<const Model> model = TurningDisk();
  SimulationOptions o;
  o.end_time = 0.1234;  // off the 1 ms grid: /time ends with a row at 0.1234
  o.output_interval = 1e-3;
  o.integrator = Ida(1e-8);
  const auto r = RunModel(*model, o, "layout");
  ASSERT_EQ(r->time.size(), 125);
  EXPECT_NEAR(r->time(124), 0.1234, 1e-15);
  for (const char* s : {"/sensors/acc_body/acceleration", "/sensors/acc_world/acceleration",
                        "/sensors/gyro/angular_velocity"})
    EXPECT_EQ(r->Read(s).rows(), 125) << s;
  EXPECT_EQ(r->Read("/sensors/acc_world/acceleration").cols(), 2);
  const Hdf5Reader& f = *r->file;
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world/acceleration", "unit"), "m/s^2");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world/acceleration", "columns"), "x,y");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world", "kind"), "accelerometer");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world", "body"), "disk");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world", "frame"), "tip");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world", "measured_in"), "world");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_body", "measured_in"), "sensor (the frame's own axes)");
  EXPECT_EQ(f.ReadAttributeText("/sensors/acc_world", "axes"), "x,y");
  EXPECT_NE(f.ReadAttributeText("/sensors", "filter_type").find("FIR"), std::string::npos);
  EXPECT_EQ(r->Attribute("/sensors", "internal_rate_hz"), 10000);
  EXPECT_EQ(r->Attribute("/sensors", "nyquist_hz"), 500);
  EXPECT_EQ(r->Attribute("/sensors", "passband_edge_vs_nyquist"), 0.8);
  EXPECT_EQ(r->Attribute("/sensors", "stopband_edge_vs_nyquist"), 1.0);
  EXPECT_GE(r->Attribute("/sensors", "measured_stopband_attenuation_db"), 100);
  const Eigen::MatrixXd taps = r->Read("/sensors/filter_taps");
  EXPECT_EQ(taps.rows() - 1, r->Attribute("/sensors", "filter_order"));
  EXPECT_NEAR(r->Attribute("/sensors", "group_delay_s"), 0.5 * (taps.rows() - 1) * 1e-4, 1e-15);
  // The last row (0.1234 s) continues the record: the body-frame centripetal acceleration
  // -omega^2 r within the odd reflection's error, |x''| tau^2 at a distance tau beyond the end
  // (x'' = -2 alpha^2 r = -20 m/s^4), tau at most the group delay, weighted by sum |h|.
  const Eigen::MatrixXd a = r->Read("/sensors/acc_body/acceleration");
  const double delay = r->Attribute("/sensors", "group_delay_s");
  EXPECT_NEAR(a(124, 0), DiskBody(0.1234)(0), 20 * delay * delay * taps.cwiseAbs().sum());
}

// ---------------------------------------------------------------------------------------------
// A run that stops: the sensors end with /time.

// Throws once the simulated time passes t_fail (a solver failure in the middle of a run).
class FailingElement final : public test_support::PlainTestElement {
 public:
  explicit FailingElement(double t_fail) : t_fail_(t_fail) {}
  const std::string& name() const override { return name_; }
  std::unique_ptr<ExternalForceWorkspace> MakeWorkspace(const Model&) const override {
    return std::make_unique<ExternalForceWorkspace>();
  }
  void Apply(const Model&, double t, Data&, ExternalForceWorkspace&) const override {
    if (t > t_fail_) throw std::runtime_error("failing element: t > " + std::to_string(t_fail_));
  }

 private:
  std::string name_ = "failing";
  double t_fail_;
};

TEST(SensorSampler, ARunThatStopsEndsItsSensorsWithTime) {
  for (const IntegratorKind kind : {IntegratorKind::kIda, IntegratorKind::kGeneralizedAlpha}) {
    ModelBuilder b;
    const BodyIndex disk = b.AddBody("disk", 2.0, Vec3::Zero(), Vec3(0.01, 0.01, 0.02).asDiagonal());
    const JointIndex j = b.AddJoint(Joint("spin", JointType::kRevolute, kWorldBody, disk));
    b.SetJointVelocity(j, Eigen::VectorXd::Constant(1, 5.0));
    b.AddExternalForce(std::make_shared<FailingElement>(0.0735));
    b.AddSensor({.name = "acc", .kind = SensorKind::kAccelerometer, .frame = b.body_frame(disk),
                 .X_FS = Transform::Translation(Vec3(0.1, 0, 0))});
    const std::shared_ptr<const Model> model = std::move(b).Finalize();
    SimulationOptions o;
    o.end_time = 1.0;
    o.output_interval = 1e-3;
    o.integrator.kind = kind;
    o.integrator.step = 1e-4;
    // IDA on a uniform spin would take steps of centiseconds: the last row before the failure
    // then lies that far back. Bounded steps make the bound below hold for both integrators.
    o.integrator.max_step = 5e-3;
    const std::string path = ::testing::TempDir() + "orrery_sensors_stop_" + std::to_string(::getpid()) + ".h5";
    {
      ResultFile out = ResultFile::Create(path);
      EXPECT_THROW(Simulate(*model, o, &out), std::runtime_error);
    }
    Hdf5Reader in(path);
    const Eigen::MatrixXd t = in.ReadMatrix("/time"), a = in.ReadMatrix("/sensors/acc/acceleration");
    // The last row before the failure: within one step (and one output interval) of it (IDA may
    // have stepped past an output time and failed there).
    EXPECT_LE(t(t.rows() - 1, 0), 0.0735);
    EXPECT_GE(t(t.rows() - 1, 0), 0.0735 - o.integrator.max_step - o.output_interval);
    EXPECT_EQ(a.rows(), t.rows());
    // A free disk turning at 5 rad/s: -omega^2 r along its radius, to the last row.
    EXPECT_NEAR(a(a.rows() - 1, 0), -2.5, 1e-6);
    std::filesystem::remove(path);
  }
}

}  // namespace
}  // namespace orrery
