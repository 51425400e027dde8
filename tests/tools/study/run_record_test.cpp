// Run records: the text form holds every double to the last bit and refuses incomplete text.
#include "tools/study/run_record.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace orrery::study {
namespace {

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(RunRecordTest, RoundTripKeepsEveryBit) {
  RunRecord r;
  r.run = 12345;
  r.status = RunStatus::kOutputFailed;
  r.exit_status = 137;
  r.wall_time_s = 0.1 + 0.2;  // 0.30000000000000004
  r.cpu_time_s = std::nextafter(1.0, 2.0);
  r.peak_memory_mib = 28.21875;
  r.reason = "output 'x': run.h5: /a: no such dataset";
  r.rank = 17;
  r.host = "node 3";
  r.outputs = {std::numeric_limits<double>::quiet_NaN(),
               -0.0,
               std::numeric_limits<double>::denorm_min(),
               std::numeric_limits<double>::infinity(),
               -1.0 / 3.0,
               6.02214076e23};
  r.units = {"N", "N m", "", "rad/s", "m/s^2", "1"};
  const std::string text = EncodeRunRecord(r, {"a.b=1", "c=[1, 2]"});
  const RunRecord b = DecodeRunRecord(text);
  EXPECT_EQ(b.run, r.run);
  EXPECT_EQ(b.status, r.status);
  EXPECT_EQ(b.exit_status, 137);
  EXPECT_TRUE(SameBits(b.wall_time_s, r.wall_time_s));
  EXPECT_TRUE(SameBits(b.cpu_time_s, r.cpu_time_s));
  EXPECT_TRUE(SameBits(b.peak_memory_mib, r.peak_memory_mib));
  EXPECT_EQ(b.reason, r.reason);
  EXPECT_EQ(b.rank, 17);
  EXPECT_EQ(b.host, "node 3");
  ASSERT_EQ(b.outputs.size(), r.outputs.size());
  EXPECT_TRUE(std::isnan(b.outputs[0]));
  for (std::size_t i = 1; i < r.outputs.size(); ++i)
    EXPECT_TRUE(SameBits(b.outputs[i], r.outputs[i])) << i;
  EXPECT_EQ(b.units, r.units);
  // The parameters are there for a person
  EXPECT_NE(text.find("\nparameter c=[1, 2]\n"), std::string::npos);
}

TEST(RunRecordTest, ReasonsStayOnOneLine) {
  RunRecord r;
  r.run = 1;
  r.reason = "two\nlines";
  EXPECT_EQ(DecodeRunRecord(EncodeRunRecord(r)).reason, "two lines");
}

TEST(RunRecordTest, IncompleteOrForeignTextIsRefused) {
  RunRecord r;
  r.run = 3;
  r.status = RunStatus::kOk;
  r.outputs = {1.5};
  const std::string text = EncodeRunRecord(r);
  // Cut anywhere before the end line: refused (a half-written marker is no marker)
  for (std::size_t n = 0; n + 4 < text.size(); n += 7)
    EXPECT_THROW(DecodeRunRecord(text.substr(0, n)), std::runtime_error) << n;
  EXPECT_THROW(DecodeRunRecord("hello\n"), std::runtime_error);
  std::string bad = text;
  bad.replace(bad.find("status ok"), 9, "status so");
  EXPECT_THROW(DecodeRunRecord(bad), std::runtime_error);
  std::string bad_number = text;
  bad_number.replace(bad_number.find("output 0 "), 9, "output 0 x");
  EXPECT_THROW(DecodeRunRecord(bad_number), std::runtime_error);
}

}  // namespace
}  // namespace orrery::study
