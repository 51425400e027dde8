#pragma once
// A base for test force elements that only Apply(): no tangents (the iteration matrix takes
// finite differences) and no outputs.
#include <vector>

#include "mbd/external_force.h"

namespace orrery::test_support {

class PlainTestElement : public ExternalForceElement {
 public:
  bool HasTangents() const override { return false; }
  void AddTangents(const Model&, const Data&, ExternalForceWorkspace&, Eigen::Ref<Eigen::MatrixXd>,
                   Eigen::Ref<Eigen::MatrixXd>) const override {}
  const std::vector<OutputDescription>& outputs() const override { return outputs_; }
  void GetOutputs(const ExternalForceWorkspace&, double*) const override {}

 private:
  std::vector<OutputDescription> outputs_;
};

}  // namespace orrery::test_support
