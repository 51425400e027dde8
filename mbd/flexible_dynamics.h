#pragma once
// The floating-frame terms of flexible bodies (flexible_body.h), one function per pipeline stage
// that needs them; each is called by that stage and does nothing for a model without flexible
// bodies.
#include <Eigen/Core>

#include "mbd/data.h"
#include "mbd/model.h"

namespace orrery {

// Position stage, poses (CalcFramePoses, after the body poses): the modal coordinates
// data.flex[i].qf and the poses of node frames with their modal Jacobians data.J_frame_modal.
void CalcNodeFramePoses(const Model& model, const Eigen::VectorXd& q, Data& data);

// Position stage, inertias (CalcPositionKinematics, after CalcNodeFramePoses): data.flex terms
// (S, J, D, L, F_W) and the deformed spatial inertia data.I_W of each flexible body.
void CalcFlexibleInertiaTerms(const Model& model, Data& data);

// Velocity stage: data.V_WFrame of every frame (node frames add J_frame_modal q_f-dot) and the
// modal rates data.flex[i].qf_dot.
void CalcFrameVelocities(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& v, Data& data);

// Force-element stage: elastic, damping and geometric-stiffening forces -(K + K_g) q_f - D q_f-dot
// into data.tau_applied; returns (elastic energy 1/2 q^T K q, dissipated power q-dot^T D q-dot).
std::pair<double, double> CalcFlexibleInternalForces(const Model& model, Data& data);

// Inverse-dynamics stage, forward pass: the spatial force (world origin) that body b's rigid
// frame needs for the accelerations A = data.A_WB[b] and vdot, minus data.f_ext[b], and the modal
// rows of data.tau_id (before the applied forces are subtracted).
Vec6 CalcFlexibleBodyForce(const Model& model, const FlexibleBody& fb,
                           const Eigen::Ref<const Eigen::VectorXd>& vdot, Data& data);

// Whether DaeSystem::Tangents may take flexible body i's modal columns from
// SetFlexibleModalTangents instead of differences: the body is a leaf of the tree (no joint hangs
// from it), no element of the model reads a frame on one of its nodes (such a frame moves with
// q_f), and every external element has analytic tangents (external elements may read the deformed
// body; they add their own tangents and are left out of the differences). Then q_f and q_f-dot
// reach the dynamic rows only through the body's own terms: its modal rows and the spatial force it
// hands to its ancestors. An element kind added to the model that can read a node frame must be
// checked here.
bool ModalColumnsAreLocal(const Model& model, int i);

// Flexible body i's columns (its modal coordinates) of Tangents' Kq ((nv + nc) x nv: d(r_v,
// r_lam)/d(dq)) and Cv (nv x nv: d r_v/d v) at data's state: the equations of flexible_body.h
// differentiated in q_f and q_f-dot (the invariants are constant, D_l, L_l, S, U and C linear or
// quadratic in q_f), the rows of its ancestors' coordinates by the joint subspaces, the modal rows
// with K + K_g and D; every other row zero. data must hold a whole evaluation at the state
// (kinematics, force elements, CalcInverseDynamics at vdot: A_WB). Valid when
// ModalColumnsAreLocal(model, i) and the external elements are left out of the differences.
// Allocation-free.
void SetFlexibleModalTangents(const Model& model, const Data& data, int i,
                              const Eigen::Ref<const Eigen::VectorXd>& vdot,
                              Eigen::Ref<Eigen::MatrixXd> Kq, Eigen::Ref<Eigen::MatrixXd> Cv);

// Mass-matrix stage: the rigid-modal coupling and modal blocks (the rigid block comes from the
// composite-rigid-body pass with the deformed inertia).
void AddFlexibleMassMatrix(const Model& model, Data& data);

// Kinetic energy beyond 1/2 V^T I_W V of the flexible bodies: V^T F_W q-dot + 1/2 q-dot^T M q-dot.
double FlexibleKineticEnergy(const Model& model, const Data& data);

// y = b + A x for a column-major rows x cols matrix A (leading dimension lda >= rows): the
// floating frame's O(nf^2) sums (D = I4 + I5 q, g = mode_cross q-dot). Each y_i is summed in one
// fixed order, b_i + A_i0 x_0 + A_i1 x_1 + ..., with separate multiplies and adds, so the numbers
// are the same to the bit whatever vector width the build that runs uses: AVX where the CPU has
// it (GCC or Clang on x86-64, chosen once at run time), the compiler's baseline (SSE2 on x86-64)
// otherwise. b may be null (zero); y must not alias A, x or b.
void AddColumnCombination(int rows, int cols, const double* A, long lda, const double* x,
                          const double* b, double* y);
// The builds themselves (tests call each): the baseline always, AVX where the compiler has it.
void AddColumnCombinationBaseline(int rows, int cols, const double* A, long lda, const double* x,
                                  const double* b, double* y);
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#define ORRERY_COLUMN_COMBINATION_AVX 1
void AddColumnCombinationAvx(int rows, int cols, const double* A, long lda, const double* x,
                             const double* b, double* y);
#else
#define ORRERY_COLUMN_COMBINATION_AVX 0
#endif

// Spatial momentum (world origin) of the whole model: sum of I_W V plus the flexible bodies'
// F_W q-dot. Needs the kinematics stages.
Vec6 CalcSpatialMomentum(const Model& model, const Data& data);

}  // namespace orrery
