// XDMF beside a result file (mbd/xdmf_writer.cpp): the XML is well formed (checked by a small
// strict parser below), every HDF reference names an existing dataset of the declared shape
// (checked with Hdf5Reader), grid k of a body's temporal collection selects row k of its
// positions at time /time[k], and inconsistent files are refused with the dataset named.
#include "mbd/xdmf_writer.h"

#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "mbd/hdf5_reader.h"
#include "mbd/result_file.h"

namespace orrery {
namespace {

// An XML element: name, attributes, text, children.
struct Element {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;
  std::vector<std::unique_ptr<Element>> children;

  std::vector<const Element*> All(const std::string& n) const {
    std::vector<const Element*> out;
    if (name == n) out.push_back(this);
    for (const auto& c : children) {
      const std::vector<const Element*> sub = c->All(n);
      out.insert(out.end(), sub.begin(), sub.end());
    }
    return out;
  }
};

// A strict parser for the XML subset XDMF uses: one declaration, elements, double-quoted
// attributes (unique per element), text without markup characters, no comments, entities or
// CDATA. Throws std::runtime_error at the first violation (unbalanced tags included).
class XmlParser {
 public:
  explicit XmlParser(std::string text) : s_(std::move(text)) {}

  std::unique_ptr<Element> Parse() {
    Blank();
    if (s_.compare(i_, 5, "<?xml") == 0) {
      const std::size_t end = s_.find("?>", i_);
      if (end == std::string::npos) Fail("unterminated declaration");
      i_ = end + 2;
    }
    Blank();
    std::unique_ptr<Element> root = ParseElement();
    Blank();
    if (i_ != s_.size()) Fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error("XML: " + what + " at offset " + std::to_string(i_));
  }
  void Blank() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  std::string Name() {
    const std::size_t start = i_;
    while (i_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[i_])) || s_[i_] == ':' || s_[i_] == '_' ||
                              s_[i_] == '-' || s_[i_] == '.'))
      ++i_;
    if (i_ == start || std::isdigit(static_cast<unsigned char>(s_[start]))) Fail("expected a name");
    return s_.substr(start, i_ - start);
  }
  void Expect(char c) {
    if (i_ >= s_.size() || s_[i_] != c) Fail(std::string("expected '") + c + "'");
    ++i_;
  }
  std::unique_ptr<Element> ParseElement() {
    auto e = std::make_unique<Element>();
    Expect('<');
    e->name = Name();
    // Attributes
    for (;;) {
      Blank();
      if (i_ >= s_.size()) Fail("unterminated tag");
      if (s_[i_] == '/') {
        ++i_;
        Expect('>');
        return e;
      }
      if (s_[i_] == '>') {
        ++i_;
        break;
      }
      const std::string key = Name();
      Blank();
      Expect('=');
      Blank();
      Expect('"');
      const std::size_t end = s_.find('"', i_);
      if (end == std::string::npos) Fail("unterminated attribute value");
      const std::string value = s_.substr(i_, end - i_);
      if (value.find_first_of("<&") != std::string::npos) Fail("markup in an attribute value");
      if (!e->attributes.emplace(key, value).second) Fail("duplicate attribute " + key);
      i_ = end + 1;
    }
    // Content: text and child elements up to the matching end tag
    for (;;) {
      const std::size_t lt = s_.find('<', i_);
      if (lt == std::string::npos) Fail("missing </" + e->name + ">");
      const std::string text = s_.substr(i_, lt - i_);
      if (text.find_first_of(">&") != std::string::npos) Fail("markup character in text");
      e->text += text;
      i_ = lt;
      if (s_.compare(i_, 2, "</") == 0) {
        i_ += 2;
        if (Name() != e->name) Fail("end tag does not match <" + e->name + ">");
        Blank();
        Expect('>');
        return e;
      }
      if (s_.compare(i_, 2, "<!") == 0 || s_.compare(i_, 2, "<?") == 0) Fail("unexpected markup");
      e->children.push_back(ParseElement());
    }
  }

  std::string s_;
  std::size_t i_ = 0;
};

std::string Trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \n\t"), b = s.find_last_not_of(" \n\t");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::vector<std::int64_t> Integers(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::int64_t> v;
  for (std::int64_t x; in >> x;) v.push_back(x);
  return v;
}

class XdmfWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("orrery_xdmf_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // A result file with two bodies: a tetrahedron's 4 faces (4 nodes) and a square (2 triangles,
  // 4 nodes); each node moves by 1e-3 (k + 1) (i + 1) along x at step k.
  std::string WriteResult(int rows) {
    const std::string path = (dir_ / "run.h5").string();
    ResultFile f = ResultFile::Create(path);
    const ResultFile::SeriesId t = f.AddSeries("/time", 1, "s");
    const Eigen::Matrix<std::int64_t, 4, 3> tet{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
    const Eigen::Matrix<std::int64_t, 2, 3> square{{0, 1, 2}, {0, 2, 3}};
    const Eigen::Matrix<double, 4, 3> p{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    f.WriteIntMatrix("/flexible_bodies/planet/surface/triangles", tet);
    f.WriteIntMatrix("/flexible_bodies/ring/surface/triangles", square);
    f.WriteMatrix("/flexible_bodies/planet/surface/reference_positions", p, "m");
    f.WriteMatrix("/flexible_bodies/ring/surface/reference_positions", p, "m");
    const ResultFile::SeriesId planet = f.AddSeries("/flexible_bodies/planet/surface/positions", 12, "m");
    const ResultFile::SeriesId ring = f.AddSeries("/flexible_bodies/ring/surface/positions", 12, "m");
    for (int k = 0; k < rows; ++k) {
      const double time = 0.25 * k + 0.1;
      f.Append(t, &time);
      Eigen::Matrix<double, 4, 3, Eigen::RowMajor> q = p;
      for (int i = 0; i < 4; ++i) q(i, 0) += 1e-3 * (k + 1) * (i + 1);
      f.Append(planet, q.data());
      q.col(1).array() += 2.0;
      f.Append(ring, q.data());
    }
    f.Close();
    return path;
  }

  std::filesystem::path dir_;
};

TEST_F(XdmfWriterTest, GridsReferenceExistingDatasetsRowByRow) {
  const int rows = 5;
  const std::string h5 = WriteResult(rows);
  const std::filesystem::path xdmf = WriteSurfaceXdmf(h5);
  EXPECT_EQ(xdmf, dir_ / "run.xdmf");
  std::ifstream in(xdmf);
  std::stringstream text;
  text << in.rdbuf();
  const std::unique_ptr<Element> root = XmlParser(text.str()).Parse();
  EXPECT_EQ(root->name, "Xdmf");
  EXPECT_EQ(root->attributes.at("Version"), "3.0");

  const Hdf5Reader r(h5);
  const std::vector<double> times = r.ReadVector("/time");
  // Every HDF reference: this result file, an existing dataset, the declared shape
  const std::vector<const Element*> items = root->All("DataItem");
  int hdf_items = 0;
  for (const Element* item : items) {
    if (item->attributes.count("Format") == 0 || item->attributes.at("Format") != "HDF") continue;
    ++hdf_items;
    const std::string ref = Trim(item->text);
    ASSERT_EQ(ref.rfind("run.h5:/", 0), 0u) << ref;
    const std::string path = ref.substr(7);
    ASSERT_TRUE(r.IsDataset(path)) << path;
    EXPECT_EQ(Integers(item->attributes.at("Dimensions")), r.Shape(path)) << path;
    // Integers for the triangles, doubles for the positions
    const bool triangles = path.ends_with("/triangles");
    EXPECT_EQ(item->attributes.at("NumberType"), triangles ? "Int" : "Float") << path;
  }
  // Per body: the reference grid (2 HDF items) and 2 per grid of the collection
  EXPECT_EQ(hdf_items, 2 * (2 + 2 * rows));

  // The temporal collections: grid k at time[k] selects row k of the body's positions
  int collections = 0;
  for (const Element* grid : root->All("Grid")) {
    if (grid->attributes.at("GridType") != "Collection") continue;
    ++collections;
    EXPECT_EQ(grid->attributes.at("CollectionType"), "Temporal");
    const std::string body = grid->attributes.at("Name");
    ASSERT_EQ(grid->children.size(), static_cast<std::size_t>(rows)) << body;
    const Eigen::MatrixXd positions = r.ReadMatrix("/flexible_bodies/" + body + "/surface/positions");
    for (int k = 0; k < rows; ++k) {
      const Element& step = *grid->children[k];
      const std::vector<const Element*> time = step.All("Time");
      ASSERT_EQ(time.size(), 1u);
      EXPECT_EQ(std::stod(time[0]->attributes.at("Value")), times[k]);
      const std::vector<const Element*> slabs = step.All("DataItem");
      const Element* slab = nullptr;
      for (const Element* d : slabs)
        if (d->attributes.count("ItemType") && d->attributes.at("ItemType") == "HyperSlab") slab = d;
      ASSERT_NE(slab, nullptr);
      ASSERT_EQ(slab->children.size(), 2u);
      // start (k, 0), stride (1, 1), count (1, 3 n): row k, all columns
      const std::vector<std::int64_t> selection = Integers(slab->children[0]->text);
      EXPECT_EQ(selection, (std::vector<std::int64_t>{k, 0, 1, 1, 1, positions.cols()}));
      EXPECT_EQ(Integers(slab->attributes.at("Dimensions")), (std::vector<std::int64_t>{1, positions.cols()}));
      // The selected row is the deformed surface of step k (the data written above)
      EXPECT_DOUBLE_EQ(positions(selection[0], 3), 1.0 + 2e-3 * (k + 1));
    }
  }
  EXPECT_EQ(collections, 2);
}

TEST_F(XdmfWriterTest, InconsistentFilesAndNamesAreRefused) {
  // positions with a row fewer than /time
  const std::string path = (dir_ / "short.h5").string();
  {
    ResultFile f = ResultFile::Create(path);
    f.WriteVector("/time", {0, 1, 2}, "s");
    f.WriteIntMatrix("/flexible_bodies/b/surface/triangles", Eigen::Matrix<std::int64_t, 1, 3>{{0, 1, 2}});
    f.WriteMatrix("/flexible_bodies/b/surface/reference_positions", Eigen::MatrixXd::Zero(3, 3), "m");
    f.WriteMatrix("/flexible_bodies/b/surface/positions", Eigen::MatrixXd::Zero(2, 9), "m");
  }
  try {
    WriteSurfaceXdmf(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": /flexible_bodies/b/surface/positions: expected 3 x 9 (one row per "
                                            "/time, 3 columns per surface node)");
  }
  // A missing /time names the dataset
  const std::string no_time = (dir_ / "no_time.h5").string();
  { ResultFile f = ResultFile::Create(no_time); }
  try {
    WriteSurfaceXdmf(no_time);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), no_time + ": /time: no such dataset");
  }
  // Names the XML cannot carry, empty surfaces
  const std::vector<double> times{0};
  const std::vector<XdmfSurface> bad_name{{.body = "a<b", .num_nodes = 3, .num_triangles = 1}};
  EXPECT_THROW(WriteSurfaceXdmf(dir_ / "x.h5", bad_name, times), std::invalid_argument);
  const std::vector<XdmfSurface> empty{{.body = "a", .num_nodes = 0, .num_triangles = 1}};
  EXPECT_THROW(WriteSurfaceXdmf(dir_ / "x.h5", empty, times), std::invalid_argument);
}

TEST(XdmfPathTest, ExtensionReplaced) {
  EXPECT_EQ(XdmfPathFor("results/run.h5"), std::filesystem::path("results/run.xdmf"));
  EXPECT_EQ(XdmfPathFor("run"), std::filesystem::path("run.xdmf"));
}

}  // namespace
}  // namespace orrery
