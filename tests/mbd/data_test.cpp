// data.h says who fills each field with a header `// --- Function (file.cpp) ---` per stage. The
// headers must stay true as code moves: each named file exists in mbd/ and defines the named
// function at file scope.
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct StageHeader {
  std::string function, file;
};

std::vector<StageHeader> StageHeaders(const std::string& header_text) {
  static const std::regex kHeader(R"(//\s*---\s*(\w+)\s*\(([\w/]+\.cpp)\))");
  std::vector<StageHeader> headers;
  for (auto it = std::sregex_iterator(header_text.begin(), header_text.end(), kHeader);
       it != std::sregex_iterator(); ++it)
    headers.push_back({(*it)[1], (*it)[2]});
  return headers;
}

// A definition at file scope: a line starting in column 0 with a return type, then the name, its
// parameters (which may run on to later lines) and the opening brace of its body.
bool DefinesFunction(const std::string& source, const std::string& function) {
  const std::regex definition("(^|\n)[A-Za-z][^\n;]*[ :&*]" + function + "\\([^;{]*\\{");
  return std::regex_search(source, definition);
}

TEST(DataHeader, EveryStageHeaderNamesAFileThatDefinesItsFunction) {
  const std::string dir = std::string(ORRERY_SOURCE_DIR) + "/mbd/";
  const std::string text = ReadFile(dir + "data.h");
  ASSERT_FALSE(text.empty()) << "cannot read " << dir << "data.h";
  const std::vector<StageHeader> headers = StageHeaders(text);
  // data.h has one header per stage; a regex that matched none would check nothing.
  ASSERT_GE(headers.size(), 6u);
  for (const StageHeader& h : headers) {
    const std::string source = ReadFile(dir + h.file);
    EXPECT_FALSE(source.empty()) << "data.h names mbd/" << h.file << " (for " << h.function
                                 << "), which does not exist";
    if (source.empty()) continue;
    EXPECT_TRUE(DefinesFunction(source, h.function))
        << "data.h says mbd/" << h.file << " defines " << h.function << ", but it does not";
  }
}

// The checker itself: it finds multi-line definitions and rejects calls, declarations and
// look-alike names.
TEST(DataHeader, CheckerTellsDefinitionsFromCallsAndDeclarations) {
  EXPECT_TRUE(
      DefinesFunction("#include <x>\nvoid CalcA(const Model& m,\n  Data& d) {\n}", "CalcA"));
  EXPECT_TRUE(DefinesFunction("double orrery::CalcA(int) {}", "CalcA"));
  EXPECT_FALSE(DefinesFunction("void f() {\n  CalcA(model, data);\n}", "CalcA"));
  EXPECT_FALSE(DefinesFunction("void CalcA(const Model& m);", "CalcA"));
  EXPECT_FALSE(DefinesFunction("void CalcAB(const Model& m) {}", "CalcA"));
  const auto headers =
      StageHeaders("  // --- CalcA (a.cpp), on demand ---\n  // --- scratch ---\n");
  ASSERT_EQ(headers.size(), 1u);
  EXPECT_EQ(headers[0].function, "CalcA");
  EXPECT_EQ(headers[0].file, "a.cpp");
}

}  // namespace
