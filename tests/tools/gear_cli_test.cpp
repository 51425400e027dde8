// The gear commands of the `orrery` CLI (tools/cli/modes_command.h, kinematics_command.h) on the
// scenes of models/scenes, against published tables and closed forms:
//   - `orrery modes` on the Lin & Parker (1999) scenes: Table 2 frequencies (0.05 %, the rounding
//     the validation file reports; 0.05 Hz for the lowest), classes and multiplicities
//     (rotational once, translational twice, planet N - 3 times);
//   - `orrery kinematics` on seed 001: the Willis speeds of the series scheme in 1st range
//     (w_c = w_r Z_r / (Z_s + Z_r) per stage, sun held) and Table 2's 1429 N for stage 1;
//   - the JSON output parses (a strict recursive-descent parser below, RFC 8259 grammar);
//   - the seed 002 scene runs 0.01 s through RunCommand.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>
#include <sys/wait.h>
#include <unistd.h>
#include <variant>
#include <vector>

#include <gtest/gtest.h>

#include "tools/cli/error_message.h"
#include "tools/cli/json_writer.h"
#include "tools/cli/kinematics_command.h"
#include "tools/cli/modes_command.h"
#include "tools/cli/run_command.h"

namespace orrery::cli {
namespace {

namespace fs = std::filesystem;

// ---- A minimal strict JSON parser (objects, arrays, strings with escapes, numbers, literals) ----
struct Json {
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject } type = Type::kNull;
  double number = 0;
  bool boolean = false;
  std::string string;
  std::vector<Json> array;
  std::vector<std::pair<std::string, Json>> object;
  const Json& operator[](const std::string& key) const {
    for (const auto& [k, v] : object)
      if (k == key) return v;
    throw std::out_of_range("no key " + key);
  }
  bool Has(const std::string& key) const {
    for (const auto& [k, v] : object)
      if (k == key) return true;
    return false;
  }
};

class JsonParser {
 public:
  explicit JsonParser(const std::string& text) : s_(text) {}
  Json Parse() {
    Json v = Value();
    Space();
    if (i_ != s_.size()) Fail("trailing text");
    return v;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) {
    throw std::runtime_error("JSON: " + what + " at offset " + std::to_string(i_));
  }
  void Space() { while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\n' || s_[i_] == '\r' || s_[i_] == '\t')) ++i_; }
  bool Eat(char c) {
    Space();
    if (i_ < s_.size() && s_[i_] == c) return ++i_, true;
    return false;
  }
  void Expect(char c) { if (!Eat(c)) Fail(std::string("expected '") + c + "'"); }
  std::string String() {
    Expect('"');
    std::string out;
    while (true) {
      if (i_ >= s_.size()) Fail("unterminated string");
      const char c = s_[i_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) Fail("control character in a string");
      if (c != '\\') { out += c; continue; }
      if (i_ >= s_.size()) Fail("bad escape");
      const char e = s_[i_++];
      const std::string simple = "\"\\/bfnrt", value = "\"\\/\b\f\n\r\t";
      if (const size_t k = simple.find(e); k != std::string::npos) { out += value[k]; continue; }
      if (e != 'u' || i_ + 4 > s_.size()) Fail("bad escape");
      for (int k = 0; k < 4; ++k) if (!std::isxdigit(static_cast<unsigned char>(s_[i_ + k]))) Fail("bad \\u escape");
      out += static_cast<char>(std::stoi(s_.substr(i_, 4), nullptr, 16));
      i_ += 4;
    }
  }
  Json Value() {
    Space();
    if (i_ >= s_.size()) Fail("unexpected end");
    Json v;
    const char c = s_[i_];
    if (c == '{') {
      ++i_;
      v.type = Json::Type::kObject;
      if (Eat('}')) return v;
      do {
        Space();
        std::string key = String();
        Expect(':');
        v.object.emplace_back(key, Value());
      } while (Eat(','));
      Expect('}');
    } else if (c == '[') {
      ++i_;
      v.type = Json::Type::kArray;
      if (Eat(']')) return v;
      do v.array.push_back(Value()); while (Eat(','));
      Expect(']');
    } else if (c == '"') {
      v.type = Json::Type::kString;
      v.string = String();
    } else if (s_.compare(i_, 4, "null") == 0) {
      i_ += 4;
    } else if (s_.compare(i_, 4, "true") == 0) {
      i_ += 4, v.type = Json::Type::kBool, v.boolean = true;
    } else if (s_.compare(i_, 5, "false") == 0) {
      i_ += 5, v.type = Json::Type::kBool;
    } else {
      // -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?
      const size_t start = i_;
      auto digits = [&] { const size_t d = i_; while (i_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[i_]))) ++i_; return i_ > d; };
      if (i_ < s_.size() && s_[i_] == '-') ++i_;
      if (i_ < s_.size() && s_[i_] == '0') ++i_;
      else if (!digits()) Fail("bad value");
      if (i_ < s_.size() && s_[i_] == '.') { ++i_; if (!digits()) Fail("bad fraction"); }
      if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
        ++i_;
        if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
        if (!digits()) Fail("bad exponent");
      }
      v.type = Json::Type::kNumber;
      v.number = std::stod(s_.substr(start, i_ - start));
    }
    return v;
  }
  const std::string& s_;
  size_t i_ = 0;
};

Json ParseJson(const std::string& text) { return JsonParser(text).Parse(); }

std::string Scene(const std::string& name) { return std::string(ORRERY_SOURCE_DIR) + "/models/scenes/" + name; }

TEST(JsonWriterTest, EscapesAndNumbersParseBack) {
  std::ostringstream out;
  JsonWriter w(out);
  w.BeginObject().Key("a\"b\\c\n\t\x01").String("x\"y\x1f").Key("n").BeginArray().Number(0.1).Number(-2.5e-300)
      .Number(std::nan("")).Int(-3).Bool(true).Null().EndArray().Key("e").BeginObject().EndObject().EndObject();
  const Json j = ParseJson(out.str());
  ASSERT_TRUE(j.Has("a\"b\\c\n\t\x01"));
  EXPECT_EQ(j["a\"b\\c\n\t\x01"].string, "x\"y\x1f");
  EXPECT_EQ(j["n"].array[0].number, 0.1);
  EXPECT_EQ(j["n"].array[1].number, -2.5e-300);
  EXPECT_EQ(j["n"].array[2].type, Json::Type::kNull);  // NaN
  EXPECT_EQ(j["n"].array[3].number, -3);
  EXPECT_THROW(ParseJson("{\"a\": 1,}"), std::runtime_error);  // the checker itself rejects junk
  EXPECT_THROW(ParseJson("[01]"), std::runtime_error);
}

// Table 2 of Lin & Parker (1999): rotational (once), translational (twice), planet (N - 3 times).
struct Table2 {
  std::vector<double> rotational, translational, planet;
};
Table2 LinParkerTable2(int n) {
  if (n == 3) return {{0, 1475.7, 1930.3, 2658.3, 7462.8, 11775.3}, {743.2, 1102.4, 1896.0, 2276.4, 6986.3, 9647.9}, {}};
  if (n == 4) return {{0, 1536.6, 1970.6, 2625.7, 7773.6, 13071.1}, {727.0, 1091.0, 1892.8, 2342.5, 7189.9, 10437.6}, {1808.2, 5963.8, 6981.7}};
  return {{0, 1567.4, 2006.1, 2614.8, 8065.4, 14253.1}, {710.0, 1072.0, 1888.1, 2425.3, 7382.4, 11172.3}, {1808.2, 5963.8, 6981.7}};
}

class GearCliModes : public ::testing::TestWithParam<int> {};

TEST_P(GearCliModes, LinParkerTable2FrequenciesClassesAndMultiplicities) {
  const int n = GetParam();
  ModesArgs args;
  args.scene_path = Scene("lin_parker_1999_n" + std::to_string(n) + ".yaml");
  args.json = true;
  std::ostringstream out, err;
  ASSERT_EQ(ModesCommand(args, out, err), kExitSuccess) << err.str();
  const Json j = ParseJson(out.str());
  // Expected: (frequency, class, multiplicity), ascending.
  const Table2 t = LinParkerTable2(n);
  std::vector<std::tuple<double, std::string, int>> expected;
  for (double f : t.rotational) expected.emplace_back(f, f == 0 ? "rigid_body" : "rotational", 1);
  for (double f : t.translational) expected.emplace_back(f, "translational", 2);
  for (double f : t.planet) expected.emplace_back(f, "planet", n - 3);
  std::sort(expected.begin(), expected.end());
  auto tolerance = [](double f) { return std::max(5e-4 * f, 0.05); };
  // frequencies_hz: every mode, a repeated one as often as it repeats.
  std::vector<double> all;
  for (const auto& [f, c, m] : expected) all.insert(all.end(), m, f);
  const Json& freqs = j["frequencies_hz"];
  ASSERT_EQ(freqs.array.size(), all.size());
  ASSERT_EQ(all.size(), static_cast<size_t>(3 * (n + 3)));
  for (size_t i = 0; i < all.size(); ++i) EXPECT_NEAR(freqs.array[i].number, all[i], tolerance(all[i])) << "mode " << i;
  // modes: one entry per distinct frequency with its class and multiplicity.
  const Json& modes = j["modes"];
  ASSERT_EQ(modes.array.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    const auto& [f, c, m] = expected[i];
    EXPECT_NEAR(modes.array[i]["frequency_hz"].number, f, tolerance(f)) << i;
    EXPECT_EQ(modes.array[i]["class"].string, c) << f;
    EXPECT_EQ(modes.array[i]["multiplicity"].number, m) << f;
  }
}

INSTANTIATE_TEST_SUITE_P(Planets, GearCliModes, ::testing::Values(3, 4, 5));

TEST(GearCli, Seed001KinematicsGivesWillisSpeedsAndTableTwoForce) {
  KinematicsArgs args;
  args.scene_path = Scene("seed001_three_stage.yaml");
  args.json = true;
  std::ostringstream out, err;
  ASSERT_EQ(KinematicsCommand(args, out, err), kExitSuccess) << err.str();
  const Json j = ParseJson(out.str());
  EXPECT_EQ(j["range"].string, "1st");
  // Willis, sun held, ring in: w_c = w_r Z_r / (Z_s + Z_r), stage by stage along the series chain.
  const double w = 3000 * 2 * std::numbers::pi / 60, c = 70.0 / 104.0;
  const Json& m = j["members"];
  const std::vector<std::pair<std::string, double>> speeds = {
      {"S1.ring", w}, {"S1.carrier", w * c}, {"S1.sun", 0}, {"S3.ring", w * c}, {"S3.carrier", w * c * c},
      {"S3.sun", 0}, {"S2.ring", w * c * c}, {"S2.carrier", w * c * c * c}, {"S2.sun", 0}};
  for (const auto& [name, value] : speeds) EXPECT_NEAR(m[name]["speed_rad_s"].number, value, 1e-10 * w) << name;
  // Input torque on the ring, output -T ratio.
  EXPECT_NEAR(m["S1.ring"]["external_torque_n_m"].number, 300.0, 1e-9);
  EXPECT_NEAR(j["ratio"].number, std::pow(104.0 / 70.0, 3), 1e-12);
  // Table 2, 1st range, stage 1: 1429 N (printed to 1 N) on both meshes.
  for (const Json& mesh : j["meshes"].array) {
    ASSERT_TRUE(mesh.Has("contact_ratio") && mesh.Has("c_prime_th") && mesh.Has("tvms_mean_n_per_m"));
    if (mesh["stage"].string != "S1") continue;
    EXPECT_NEAR(mesh["static_force_n"].number, 1429, 0.5) << mesh["name"].string;
    // Mesh frequency: Z_r |w_r - w_c| / 2 pi.
    EXPECT_NEAR(mesh["mesh_frequency_hz"].number, 70 * w * (1 - c) / (2 * std::numbers::pi), 1e-9);
    // Geometry from the tooth forms: base radii r cos(alpha), contact ratio > 1, ISO values.
    EXPECT_EQ(mesh["contact_ratio"].type, Json::Type::kNumber) << mesh["name"].string;
    EXPECT_GT(mesh["contact_ratio"].number, 1.0);
    EXPECT_GT(mesh["c_gamma_alpha"].number, mesh["c_gamma_beta"].number);
    EXPECT_GT(mesh["tvms_mean_n_per_m"].number, 0);
  }
  EXPECT_EQ(j["fault_frequencies_hz"].type, Json::Type::kObject);
  EXPECT_NEAR(j["fault_frequencies_hz"]["S1.sun"].number, 4 * w * c / (2 * std::numbers::pi), 1e-9);  // n |w_s - w_c|
}

// Seed 003's scenes at their published operating point (docs/validation/scenarios.md, Table 1 of
// the paper): case 1 (ring +80.6, sun -10 rad/s) mesh frequency 220.3 Hz, planet 15.74 Hz
// relative to the carrier; case 2 (sun -30 rad/s by --set) 268.9 Hz (Willis; the paper prints
// 269.1) and 19.21 Hz, to the published digits. The broken-tooth scenes list their fault with the
// planet's fault frequency (once per relative planet turn, for each of its two meshes: 2 f_p).
// The flexible scenes are read without their flexible body (kinematics makes no reduced-body file).
TEST(GearCli, Seed003ScenesRunAtThePublishedOperatingPoints) {
  for (const char* level : {"lumped", "contact", "flexible"}) {
    for (const char* variant : {"healthy", "broken_tooth"}) {
      const std::string name = std::string("seed003_") + level + "_" + variant + ".yaml";
      for (const auto& [sun, f_mesh, f_planet] : {std::tuple{-10.0, 220.3, 15.74}, std::tuple{-30.0, 268.9, 19.21}}) {
        KinematicsArgs args;
        args.scene_path = Scene(name);
        args.json = true;
        if (std::string(level) == "flexible") args.overrides.push_back("gear_train.dynamics.flexible_bodies=null");
        if (sun != -10.0) args.overrides.push_back("gear_train.input_speeds.1=-30");
        std::ostringstream out, err;
        ASSERT_EQ(KinematicsCommand(args, out, err), kExitSuccess) << name << ": " << err.str();
        const Json j = ParseJson(out.str());
        EXPECT_NEAR(j["stage_mesh_frequencies_hz"]["S"].number, f_mesh, 0.05) << name << " sun " << sun;
        EXPECT_NEAR(j["planet_sets"]["S.planet"]["relative_frequency_hz"].number, f_planet, 0.005) << name;
        EXPECT_NEAR(j["members"]["S.sun"]["speed_rad_s"].number, sun, 1e-12) << name;
        const Json& faults = j["scene_faults"];
        if (std::string(variant) == "healthy") {
          EXPECT_TRUE(faults.array.empty()) << name;
          continue;
        }
        ASSERT_EQ(faults.array.size(), 1u) << name;
        EXPECT_EQ(faults.array[0]["gear"].string, "S.planet");
        EXPECT_EQ(faults.array[0]["branch"].number, 1);
        EXPECT_EQ(faults.array[0]["kind"].string, "broken_tooth");
        EXPECT_NEAR(faults.array[0]["fault_frequency_hz"].number, 2 * f_planet, 0.01) << name;
      }
    }
  }
}

TEST(GearCli, ModesOfSeed001AndOfAGenericScene) {
  for (const std::string name : {"seed001_three_stage.yaml", "pendulum.yaml"}) {
    ModesArgs args;
    args.scene_path = Scene(name);
    args.json = true;
    std::ostringstream out, err;
    ASSERT_EQ(ModesCommand(args, out, err), kExitSuccess) << err.str();
    const Json j = ParseJson(out.str());
    ASSERT_FALSE(j["modes"].array.empty());
    if (name == "pendulum.yaml") {
      EXPECT_EQ(j["modes"].array[0]["class"].string, "mode");
    }
    else EXPECT_EQ(j["modes"].array[0]["class"].string, "rigid_body");  // a free train (Table 3)
  }
}

TEST(GearCli, KinematicsErrorsAreOneLine) {
  KinematicsArgs args;
  args.scene_path = Scene("seed001_three_stage.yaml");
  args.range = "5th";
  std::ostringstream out, err;
  EXPECT_EQ(KinematicsCommand(args, out, err), kExitFailure);
  EXPECT_EQ(err.str(), "orrery: error: --range: no gear range named '5th' (ranges: 1st, 2nd, 3rd, 4th)\n");
  args.range = "";
  args.scene_path = Scene("pendulum.yaml");
  err.str("");
  EXPECT_EQ(KinematicsCommand(args, out, err), kExitFailure);
  EXPECT_NE(err.str().find("kinematics needs a gear_train or lumped_stage scene"), std::string::npos);
}

TEST(GearCli, Seed002RunsThroughRunCommand) {
  const fs::path dir = fs::temp_directory_path() / ("orrery_gear_cli_" + std::to_string(getpid()));
  fs::create_directories(dir);
  RunArgs args;
  args.scene_path = Scene("seed002_alpha1_ramp.yaml");
  args.output_path = (dir / "seed002.h5").string();
  args.end_time = 0.01;
  args.quiet = true;
  std::ostringstream out, err;
  EXPECT_EQ(RunCommand(args, out, err), kExitSuccess) << err.str();
  EXPECT_NE(out.str().find("simulated time      0.01 s"), std::string::npos) << out.str();
  fs::remove_all(dir);
}

TEST(GearCli, BinaryModesJson) {
  const fs::path dir = fs::temp_directory_path() / ("orrery_gear_cli_bin_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string file = (dir / "out.json").string();
  const std::string command = std::string("\"") + ORRERY_BINARY_DIR + "/bin/orrery\" modes \"" +
                              Scene("lin_parker_1999_n3.yaml") + "\" --json >" + file + " 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  std::stringstream text;
  text << std::ifstream(file).rdbuf();
  fs::remove_all(dir);
  const Json j = ParseJson(text.str());
  EXPECT_EQ(j["frequencies_hz"].array.size(), 18u);
  EXPECT_NEAR(j["frequencies_hz"].array[17].number, 11775.3, 0.05);
}

}  // namespace
}  // namespace orrery::cli
