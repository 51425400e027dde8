#include "mbd/external_force.h"

namespace orrery {

int OutputValueCount(const std::vector<OutputDescription>& outputs) {
  int n = 0;
  for (const OutputDescription& o : outputs) n += o.columns;
  return n;
}

}  // namespace orrery
