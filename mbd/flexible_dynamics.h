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
