#include "mbd/triangle_mesh.h"

#include <map>
#include <utility>

namespace orrery {

double EnclosedVolume(const TriangleMesh& mesh) {
  // Signed tetrahedra from the origin to each triangle.
  double six_v = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

int CountOpenOrInconsistentEdges(const TriangleMesh& mesh) {
  // Count each directed edge; a consistent closed mesh has every directed edge exactly once and
  // its reverse exactly once.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  int bad = 0;
  for (const auto& [edge, count] : directed) {
    auto reverse = directed.find({edge.second, edge.first});
    const int reverse_count = reverse == directed.end() ? 0 : reverse->second;
    if (count != 1 || reverse_count != 1) ++bad;
  }
  return bad;
}

}  // namespace orrery
