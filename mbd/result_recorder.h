#pragma once
// What a run writes to its result file, and the computation of the recorded quantities.
//
// Layout (SI units; every series has attributes "unit" and, where useful, "columns"):
//   /time                                  s
//   /bodies/<name>/position                m      body frame origin, world axes
//   /bodies/<name>/orientation             1      quaternion (w, x, y, z) of R_WB
//   /bodies/<name>/linear_velocity         m/s    of the body frame origin
//   /bodies/<name>/angular_velocity        rad/s  world axes
//   /bodies/<name>/linear_acceleration     m/s^2  of the body frame origin
//   /bodies/<name>/angular_acceleration    rad/s^2
//   /joints/<name>/q, /joints/<name>/v     rad or m (per coordinate; quaternions 1), rad/s or m/s
//   /joints/<name>/reaction                N, N m: wrench the parent exerts on the child through
//                                          the joint, at the origin of frame M, world axes
//   /loop_closures/<name>/reaction         N, N m: wrench on frame B's body at B's origin
//   /drivers/<name>/effort                 N m or N: the driving torque or force (-lambda)
//   /gear_meshes/<name>/force              N: tooth force along the engaged flank's normal
//   /gear_meshes/<name>/deflection         m: compression of the engaged flank
//   /gear_meshes/<name>/stiffness          N/m at the current mesh phase
//   /gear_meshes/<name>/contact            1: +1 drive flank, -1 coast flank, 0 teeth apart
//   /gear_meshes/<name>/phase              cycles: mesh phase
//   /gear_constraints/<name>/force         N: tooth force of an ideal mesh (its multiplier)
//   /energy                                J: kinetic, gravity potential, elastic potential
//   /power                                 W: applied loads, drivers, dissipated by dampers
//                                          (integrated, the energy balance of a run)
//   /constraints/drift                     max |Phi|, max |G v + g_t| per row
//   /flexible_bodies/<name>/modal_q, modal_v   modal coordinates (mass-normalized: kg^0.5 m) and
//                                          their rates; attribute "frequencies_hz"
//   /flexible_bodies/<name>/von_mises_max  Pa, node id, x, y, z (m, body frame): the largest von
//                                          Mises stress over the stress nodes and where (bodies
//                                          with stress modes)
//   /flexible_bodies/<name>/surface/...    triangles, reference_positions and, per step,
//                                          positions (world) of the surface nodes (bodies with
//                                          record_surface; layout of xdmf_writer.h)
//   /flexible_bodies/<name>/node_sets/<set>/displacement   m: elastic displacements of the set's
//                                          nodes in the body frame (record_node_sets)
//   /external/<name>/<output>              outputs of external force elements (contact)
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"
#include "mbd/result_file.h"
#include "mbd/state.h"
#include "mbd/stress_hot_spot.h"

namespace orrery {

class ResultRecorder {
 public:
  // Declares every series in `out`. The recorder keeps references to both.
  ResultRecorder(const Model& model, ResultFile& out);
  // Computes and appends one row of every series at (state, vdot, lambda). Allocation-free.
  // warm: a Data of the same model evaluated near the state (the integrator's,
  // Integrator::data()), whose external elements' tracking state is copied into the recorder's
  // before its evaluation (WarmStartExternalWorkspaces): the contacts then track from a step
  // back instead of from the last row; the row is the same.
  // at_state: a Data of the same model whose last evaluation was at exactly (state, vdot)
  // (Integrator::DataAtState) on a model without constraints: the row is read from it and the
  // recorder evaluates nothing (the same numbers to the last bit); ignored with constraints.
  void Record(const State& state, const Eigen::VectorXd& vdot, const Eigen::VectorXd& lambda,
              const Data* warm = nullptr, const Data* at_state = nullptr);
  // The pipeline at the last Record()'s row (energies, powers, constraints): the recorder's own
  // evaluation or the at_state Data it read.
  const Data& data() const { return *row_data_; }

 private:
  const Model& model_;
  ResultFile& out_;
  Data data_;
  const Data* row_data_ = &data_;  // what the last row was read from
  ResultFile::SeriesId time_, energy_, power_, drift_;
  struct BodySeries { ResultFile::SeriesId p, quat, v, w, a, alpha; };
  std::vector<BodySeries> bodies_;          // per body (index 0 unused)
  std::vector<ResultFile::SeriesId> joint_q_, joint_v_, joint_reaction_;  // per joint
  std::vector<ResultFile::SeriesId> loop_reaction_, driver_effort_;
  struct MeshSeries { ResultFile::SeriesId force, deflection, stiffness, contact, phase; };
  std::vector<MeshSeries> meshes_;
  std::vector<ResultFile::SeriesId> gear_constraint_force_;
  struct FlexSeries {
    ResultFile::SeriesId q = -1, v = -1, von_mises = -1, surface = -1;
    std::unique_ptr<StressHotSpot> hot_spot;  // von_mises' point (stress_hot_spot.h)
    std::vector<int> surface_nodes;  // indices into the modes' nodes
    std::vector<ResultFile::SeriesId> node_sets;  // per FlexibleBodyOptions::record_node_sets
    std::vector<const std::vector<int>*> node_set_nodes;  // their nodes (in the model's modes)
  };
  std::vector<FlexSeries> flex_;
  std::vector<std::vector<ResultFile::SeriesId>> external_;
  std::vector<std::vector<int>> external_offsets_;  // first value of each output in a row
  Eigen::VectorXd surface_row_;                     // scratch
  Eigen::VectorXd row_;                     // scratch
  // The row of every series above, appended at once (ResultFile::AppendRow): the series' ids run
  // from first_ (time_) to first_ + count_ - 1 in the order the constructor added them, and
  // staged_ holds their columns one after the other (series id - first_ starts at offset_).
  ResultFile::SeriesId first_ = 0;
  int count_ = 0;
  std::vector<int> offset_;
  Eigen::VectorXd staged_;
  // Series `id`'s columns in staged_.
  double* Slot(ResultFile::SeriesId id) { return staged_.data() + offset_[id - first_]; }
  // Copies n doubles from x to series `id`'s columns in staged_.
  template <int N>
  void Put(ResultFile::SeriesId id, const double* x) {
    double* to = Slot(id);
    for (int c = 0; c < N; ++c) to[c] = x[c];
  }
};

}  // namespace orrery
