#include "contact/contact_point_record.h"

#include <limits>

namespace orrery::contact {

void ContactPointRecord::Write(int n, double* positions, double* forces) const {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  // Selection without scratch: the next largest below the last taken, O(n #points).
  double last_force = std::numeric_limits<double>::infinity();
  int last = -1;
  for (int slot = 0; slot < n; ++slot) {
    int best = -1;
    for (int i = 0; i < static_cast<int>(forces_.size()); ++i) {
      const bool below_last = forces_[i] < last_force || (forces_[i] == last_force && i > last);
      if (below_last && (best < 0 || forces_[i] > forces_[best])) best = i;
    }
    if (best < 0) {
      for (int k = 0; k < 3; ++k) positions[3 * slot + k] = kNaN;
      forces[slot] = kNaN;
      continue;
    }
    for (int k = 0; k < 3; ++k) positions[3 * slot + k] = positions_[best](k);
    forces[slot] = forces_[best];
    last_force = forces_[best];
    last = best;
  }
}

}  // namespace orrery::contact
