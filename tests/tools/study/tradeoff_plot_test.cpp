// tools/plot/tradeoff_plot.py on a small synthetic trade study (one study of three runs whose
// errors are worked out by hand): the table lands between the doc's markers, the PNG is written,
// and a doc without markers is one line, exit 2. Needs python3-matplotlib (skipped without it).
#include "tests/tools/study/study_cli_support.h"

namespace orrery::study::test {
namespace {

class TradeoffPlotTest : public StudyCliTest {
 protected:
  CommandResult Plot(const std::string& doc) const {
    return Shell("/usr/bin/python3 '" + std::string(ORRERY_SOURCE_DIR) +
                 "/tools/plot/tradeoff_plot.py' --studies '" + Path("studies") + "' --images '" +
                 Path("images") + "' --doc '" + doc + "'");
  }
};

TEST_F(TradeoffPlotTest, WritesTheTableBetweenTheMarkersAndThePlots) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib, numpy' 2>/dev/null") != 0)
    GTEST_SKIP() << "python3-matplotlib not installed";
  fs::create_directories(dir_ / "studies/seed003_lumped_healthy");
  // Runs 0 and 1 against the reference (run 2, 100 N): 1 % and 0.5 %; run 1 is the scene's
  // default (IDA, rtol 1e-06, 0.1 ms output)
  Write("studies/seed003_lumped_healthy/index.csv",
        "run,status,solver.integrator,solver.rtol,output.interval,mesh_force_peak,wall_time_s,"
        "cpu_time_s,peak_memory_mib,exit_status,reason,rank,host,result_file\n"
        "0,ok,ida,1e-04,1e-04,101,2,1,30,0,,0,h,runs/run_00000.h5\n"
        "1,ok,ida,1e-06,1e-04,99.5,3,2,30,0,,0,h,runs/run_00001.h5\n"
        "2,ok,ida,1e-09,5e-05,100,9,4,31,0,,0,h,runs/run_00002.h5\n");
  const std::string doc = Write("doc.md",
                                "# T\n<!-- tradeoff-table:start -->\nold\n"
                                "<!-- tradeoff-table:end -->\nafter\n");
  const CommandResult r = Plot(doc);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = ReadFile(doc);
  EXPECT_EQ(text.find("old"), std::string::npos);
  EXPECT_NE(text.find("| lumped TVMS | 0: IDA, rtol 1e-04, out 1e-04 | 1 | 2 | 30 | 1 % |"),
            std::string::npos)
      << text;
  EXPECT_NE(
      text.find("| lumped TVMS | 1: IDA, rtol 1e-06, out 1e-04 **default** | 2 | 3 | 30 | 0.5 % |"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("(reference) | 4 | 9 | 31 | 100 |"), std::string::npos) << text;
  EXPECT_NE(text.find("seed003_contact_healthy: not run"), std::string::npos);
  EXPECT_NE(text.find("after\n"), std::string::npos);
  EXPECT_GT(fs::file_size(Path("images/tradeoff_seed003_healthy.png")), 1000u);

  const CommandResult bad = Plot(Write("plain.md", "# no markers\n"));
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err,
            "orrery plot: error: --doc " + Path("plain.md") +
                ": no <!-- tradeoff-table:start --> ... <!-- tradeoff-table:end --> markers\n");
}

}  // namespace
}  // namespace orrery::study::test
