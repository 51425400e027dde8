// models/studies/quick.yaml run on one machine and with `mpirun -n 2`: the same index, every
// parameter and output equal to the last bit (the runs are deterministic, and records travel as
// hexadecimal doubles); only the measured wall time, CPU time, memory and who ran each run differ.
#include <cstring>
#include <set>

#include "mbd/hdf5_reader.h"
#include "tests/tools/study/study_cli_support.h"

namespace orrery::study::test {
namespace {

// Columns that measure the run rather than compute it
bool Measured(const std::string& column) {
  static const std::set<std::string> kMeasured{"wall_time_s", "cpu_time_s", "peak_memory_mib",
                                               "rank", "host"};
  return kMeasured.count(column) > 0;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST_F(StudyCliTest, QuickStudyUnderMpiEqualsTheSerialOne) {
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "mpirun not found: install Debian's openmpi-bin (tools/install_deps.sh does)";
  const std::string study = std::string(ORRERY_SOURCE_DIR) + "/models/studies/quick.yaml";
  // Serial, one run at a time
  const CommandResult serial = Study(study + " -o " + Path("serial") + " -j 1 --quiet");
  ASSERT_EQ(serial.status, 0) << serial.err;
  // Two ranks (as root in CI, and on machines with fewer cores than ranks)
  const CommandResult mpi = Shell("mpirun --allow-run-as-root --oversubscribe -n 2 '" + Binary() +
                                  "' study " + study + " -o " + Path("mpi") + " --quiet");
  ASSERT_EQ(mpi.status, 0) << mpi.out << mpi.err;
  EXPECT_NE(mpi.out.find("MPI, 2 ranks x 1 run at a time"), std::string::npos) << mpi.out;

  // CSV: every computed column the same text (the shortest text of the same double)
  const auto a = ReadCsv(Path("serial/index.csv")), b = ReadCsv(Path("mpi/index.csv"));
  ASSERT_EQ(a.size(), 7u);  // header and six runs
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a[0], b[0]);
  std::set<std::string> ranks;
  for (std::size_t row = 1; row < a.size(); ++row) {
    ASSERT_EQ(a[row].size(), a[0].size());
    EXPECT_EQ(a[row][1], "ok") << "run " << row - 1;
    for (std::size_t col = 0; col < a[0].size(); ++col) {
      if (a[0][col] == "rank") ranks.insert(b[row][col]);
      if (!Measured(a[0][col])) {
        EXPECT_EQ(a[row][col], b[row][col]) << a[0][col] << " of run " << row - 1;
      }
    }
  }
  EXPECT_EQ(ranks, (std::set<std::string>{"0", "1"})) << "both ranks run runs";

  // HDF5: the outputs bit for bit
  const Hdf5Reader ha(Path("serial/index.h5")), hb(Path("mpi/index.h5"));
  const std::vector<std::string> names = ha.ReadStrings("/outputs/names");
  ASSERT_EQ(names.size(), 5u);
  for (const std::string& name : names) {
    const std::vector<double> va = ha.ReadVector("/outputs/" + name),
                              vb = hb.ReadVector("/outputs/" + name);
    ASSERT_EQ(va.size(), vb.size());
    for (std::size_t i = 0; i < va.size(); ++i)
      EXPECT_TRUE(SameBits(va[i], vb[i])) << name << " of run " << i;
    EXPECT_EQ(ha.ReadStringAttribute("/outputs/" + name, "unit"),
              hb.ReadStringAttribute("/outputs/" + name, "unit"));
  }
  EXPECT_EQ(ha.ReadStringAttribute("/outputs/sun_mesh_force_peak", "unit"), "N");
  EXPECT_EQ(ha.ReadVector("/parameters/gear_train.input_speed.alpha1"),
            hb.ReadVector("/parameters/gear_train.input_speed.alpha1"));

  // Each run's result file carries its place in the study
  const Hdf5Reader run3(Path("mpi/runs/run_00003.h5"));
  EXPECT_EQ(run3.ReadIntAttribute("/study", "run"), 3);
  EXPECT_EQ(run3.ReadStringAttribute("/study", "study"), "quick");
  EXPECT_EQ(run3.ReadNumberAttribute("/study", "gear_train.input_speed.alpha1"), 0.04);
  EXPECT_EQ(run3.ReadNumberAttribute("/study", "gear_train.dynamics.mesh_damping_ratio"), 0.05);
}

}  // namespace
}  // namespace orrery::study::test
