#pragma once
// The contact points of an evaluation, kept for output when an element is asked to record them
// (ContactElementSpec / FlexibleContactElementSpec::record_points = n > 0): each row then holds
// the n points with the largest normal force, their positions in the frame of side a's body
// (for a gear contact: gear 1's body, where the points map the contact pattern on its flanks)
// and their normal forces, NaN where fewer points touch.
//   /external/<name>/point_positions   (rows x 3n, m: x0 y0 z0 x1 ...)
//   /external/<name>/point_normal_forces (rows x n, N)
// Nothing is allocated after construction (the lists are reserved for every node of both
// surfaces).
#include <vector>

#include "mbd/spatial.h"

namespace orrery::contact {

class ContactPointRecord {
 public:
  // capacity: the most points an evaluation can have (nodes of both surfaces).
  explicit ContactPointRecord(int capacity = 0) {
    positions_.reserve(capacity);
    forces_.reserve(capacity);
  }
  void Clear() {
    positions_.clear();
    forces_.clear();
  }
  void Add(const Vec3& p_A, double normal_force) {
    positions_.push_back(p_A);
    forces_.push_back(normal_force);
  }
  // The n largest points by force (ties by the order added) into positions (3n) and forces (n).
  void Write(int n, double* positions, double* forces) const;

 private:
  std::vector<Vec3> positions_;
  std::vector<double> forces_;
};

}  // namespace orrery::contact
