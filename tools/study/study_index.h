#pragma once
// The index of a study: one row per run with its parameters, its extracted outputs and how it
// went, as a CSV table and as HDF5, both rewritten whole (to a temporary file, then renamed) so
// a reader never sees half a table.
//
// Columns, in this order:
//   run                 run index
//   status              ok | failed | output_failed | pending (no record yet)
//   <scene key> ...     the parameters (numbers when every value of the key is one, else text)
//   <output name> ...   the outputs (NaN when not extracted)
//   wall_time_s, cpu_time_s, peak_memory_mib    measured for the run's process
//   exit_status         the run's exit code (128 + n for signal n; -1: did not start)
//   reason              why a run failed ("" for ok)
//   rank, host          the MPI rank (0 without MPI) and the machine that ran it
//   result_file         the run's result file, relative to the study folder
//
// CSV: RFC 4180 (a header line, fields with commas, quotes or line breaks quoted); numbers as
// the shortest text that reads back as the same double (std::to_chars), NaN as "nan", an empty
// field where a pending run has no value.
// HDF5: /runs/{run, status, exit_status, reason, rank, host, result_file, wall_time_s, cpu_time_s,
// peak_memory_mib}, /parameters/<key> (with /parameters/keys listing the keys in order),
// /outputs/<name> with its "unit" (from the first run that had one; /outputs/names in order);
// root attributes study, study_file, study_hash, scene, runs, ok, failed, output_failed, pending.
//
// Usage:
//   std::vector<std::optional<RunRecord>> records(plan.runs.size());
//   WriteStudyIndex(plan, folder, records, study_hash);
#include <optional>
#include <string>
#include <vector>

#include "tools/study/run_record.h"
#include "tools/study/study_folder.h"
#include "tools/study/study_plan.h"

namespace orrery::study {

struct StudyCounts {
  int ok = 0, failed = 0, output_failed = 0, pending = 0;
};
StudyCounts CountRecords(const std::vector<std::optional<RunRecord>>& records);

// Writes folder.IndexCsvPath() and folder.IndexHdf5Path() from `records` (one per run of the
// plan). Throws std::runtime_error naming the file when one cannot be written.
void WriteStudyIndex(const StudyPlan& plan, const StudyFolder& folder,
                     const std::vector<std::optional<RunRecord>>& records,
                     const std::string& study_hash);

// The CSV text alone (tests).
std::string StudyIndexCsv(const StudyPlan& plan, const StudyFolder& folder,
                          const std::vector<std::optional<RunRecord>>& records);

}  // namespace orrery::study
