#pragma once
// A STEP file of a generated gear, made by gmsh's OpenCASCADE kernel from the project's own
// outline (models/gear_geometry.h SampleGearOutline: 16 intervals per involute): one spline per
// profile segment of every tooth through the sampled exact points, the bore circle, the face
// extruded over the face width; millimetres. The same construction as
// tools/benchmarks/import_benchmark.cpp's planet. Needs the gmsh program (the caller checks);
// throws std::runtime_error when gmsh fails.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/gear_geometry.h"

namespace orrery::test_support {

inline std::filesystem::path WriteGearStep(const std::filesystem::path& dir,
                                           const gears::Gear& gear, double bore_m,
                                           const std::string& name = "planet") {
  std::ofstream geo(dir / (name + ".geo"));
  geo.precision(17);
  geo << "SetFactory(\"OpenCASCADE\");\n";
  const std::vector<gears::ProfilePoint> outline =
      gear.SampleGearOutline({.root = 4, .fillet = 8, .involute = 16, .tip = 4});
  const int n = static_cast<int>(outline.size());
  for (int i = 0; i < n; ++i)
    geo << "Point(" << i + 1 << ") = {" << outline[i].p.x() * 1e3 << ", " << outline[i].p.y() * 1e3
        << ", 0};\n";
  // Runs of points of one segment, each a spline from its first point to the next run's first
  std::vector<int> curves;
  for (int i = 0; i < n;) {
    int j = i + 1;
    while (j < n && outline[j].segment == outline[i].segment && outline[j].s > outline[j - 1].s)
      ++j;
    const int id = static_cast<int>(curves.size()) + 1;
    geo << (j - i == 1 ? "Line(" : "Spline(") << id << ") = {";
    for (int k = i; k <= j; ++k) geo << (k == i ? "" : ", ") << (k % n) + 1;
    geo << "};\n";
    curves.push_back(id);
    i = j;
  }
  geo << "Curve Loop(1) = {";
  for (std::size_t c = 0; c < curves.size(); ++c) geo << (c ? ", " : "") << curves[c];
  geo << "};\nCircle(" << curves.size() + 1 << ") = {0, 0, 0, " << bore_m * 1e3
      << "};\nCurve Loop(2) = {" << curves.size() + 1
      << "};\nPlane Surface(1) = {1, 2};\nExtrude {0, 0, " << gear.spec().face_width_m * 1e3
      << "} { Surface{1}; }\n";
  geo.close();
  const std::string command = "cd '" + dir.string() + "' && gmsh " + name + ".geo -0 -o " + name +
                              ".step -format step > " + name + "_gmsh.log 2>&1";
  if (std::system(command.c_str()) != 0)
    throw std::runtime_error("gmsh could not write the gear STEP: " + command);
  return dir / (name + ".step");
}

}  // namespace orrery::test_support
