#pragma once
// What each fuzzer does with one input: the file readers of the repository (STL, OBJ, gmsh .msh,
// Abaqus/CalculiX .inp, FE matrices and DOF tables, YAML scenes), fed arbitrary bytes. A reader
// may refuse an input with an exception derived from std::exception (that is its job); anything
// else (a crash, an abort, a sanitizer report, a leak, a hang, memory beyond the limit) is a bug.
// Header-only, so that the libFuzzer programs (tools/fuzz/fuzz_main.cpp, built by
// tools/fuzz/run_fuzz.sh with clang) and the regression test that replays the corpus and every
// input a fuzzer once broke (tests/tools/fuzz_regression_test.cpp, with the normal build) run the
// same code.
//
// Usage:
//   for (const orrery::fuzz::Target& t : orrery::fuzz::kTargets) t.run(data, size);
#include <cstddef>
#include <cstdint>
#include <exception>
#include <sstream>
#include <string>
#include <string_view>

#include "flex/inp_file.h"
#include "import/fe_matrices.h"
#include "import/mass_properties.h"
#include "import/mesh_checks.h"
#include "import/msh_reader.h"
#include "import/obj_reader.h"
#include "import/scene.h"
#include "import/stl_reader.h"
#include "import/surface_mesh.h"

namespace orrery::fuzz {

inline std::string_view Bytes(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A surface from a reader, then everything import does with it: weld, checks, mass properties.
inline void Surface(const RawSurface& raw) {
  SurfaceMesh s = WeldRawSurface(raw, 1.0, "fuzz");
  const MeshCheckReport r = CheckMesh(s.mesh);
  OrientMesh(s.mesh, r);
  if (r.watertight() && r.non_orientable_components == 0) CalcMassProperties(s.mesh, 1.0);
}

inline void FuzzStl(const std::uint8_t* data, std::size_t size) {
  try {
    Surface(ParseStl(Bytes(data, size), "fuzz.stl"));
  } catch (const std::exception&) {
  }
}

inline void FuzzObj(const std::uint8_t* data, std::size_t size) {
  try {
    Surface(ParseObj(Bytes(data, size), "fuzz.obj"));
  } catch (const std::exception&) {
  }
}

inline void FuzzMsh(const std::uint8_t* data, std::size_t size) {
  try {
    const GmshMesh m = ParseGmshMsh(Bytes(data, size), "fuzz.msh");
    if (!m.surface.triangles.empty()) Surface(m.surface);
  } catch (const std::exception&) {
  }
}

inline void FuzzInp(const std::uint8_t* data, std::size_t size) {
  try {
    std::istringstream in{std::string(Bytes(data, size))};
    flex::ParseInp(in, "fuzz.inp");
  } catch (const std::exception&) {
  }
}

// The first byte picks the reader: Matrix Market, a CalculiX matrix (the next byte its size), a
// DOF table.
inline void FuzzMatrix(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return;
  try {
    const std::string_view rest = Bytes(data + 2, size - 2);
    switch (data[0] % 3) {
      case 0: ParseMatrixMarket(Bytes(data + 1, size - 1), "fuzz.mtx"); break;
      case 1: ParseCalculixMatrix(rest, 1 + data[1] % 64, "fuzz.sti"); break;
      default: ParseDofTable(Bytes(data + 1, size - 1), "fuzz.dof"); break;
    }
  } catch (const std::exception&) {
  }
}

inline void FuzzScene(const std::uint8_t* data, std::size_t size) {
  try {
    LoadSceneFromString(std::string(Bytes(data, size)), "fuzz.yaml");
  } catch (const std::exception&) {
  }
}

struct Target {
  const char* name;  // the fuzzer program is fuzz_<name>, its corpus tools/fuzz/corpus/<name>
  void (*run)(const std::uint8_t*, std::size_t);
};

inline constexpr Target kTargets[] = {{"stl", FuzzStl}, {"obj", FuzzObj},       {"msh", FuzzMsh},
                                      {"inp", FuzzInp}, {"matrix", FuzzMatrix}, {"scene", FuzzScene}};

}  // namespace orrery::fuzz
