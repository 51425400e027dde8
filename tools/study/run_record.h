#pragma once
// What a finished run of a study leaves: its status, the reason of a failure, the extracted
// outputs, wall time and peak memory. A record is written as the run's completion marker
// (study_folder.h) and sent from an MPI rank to rank 0 (study_mpi.h) in one text form:
//
//   orrery-study-run 1
//   run 3
//   status ok                      ok | failed | output_failed
//   exit_status 0                  the child's exit code; 128 + n when killed by signal n
//   wall_time_s 0x1.3ae147ae147aep-1
//   cpu_time_s 0x1.2ae147ae147aep-1
//   peak_memory_mib 0x1.2cp+5
//   rank 1                         the MPI rank that ran it (0 without MPI)
//   host node17                    the machine it ran on
//   reason <one line>              "" for ok
//   output 0 0x1.8p+3 N            index of the study output, value, unit (rest of the line)
//   parameter solver.step=1e-4     for a reader; not read back
//
// Numbers are C99 hexadecimal floating point (printf "%a"), so a record read back holds the same
// doubles to the last bit, on every rank: the index of a study run under MPI equals that of the
// same study run on one machine. NaN is written "nan".
//
// Usage:
//   std::string text = EncodeRunRecord(record, {"solver.step=1e-4"});
//   RunRecord back = DecodeRunRecord(text);    // == record
#include <string>
#include <string_view>
#include <vector>

namespace orrery::study {

enum class RunStatus {
  kOk,            // the run finished and every output was extracted
  kFailed,        // the run failed: non-zero exit, a signal, a limit, or it could not start
  kOutputFailed,  // the run finished; an output could not be extracted (its value is NaN)
};
std::string_view RunStatusName(RunStatus status);  // "ok", "failed", "output_failed"

struct RunRecord {
  int run = -1;
  RunStatus status = RunStatus::kFailed;
  int exit_status = 0;         // exit code, 128 + signal number when killed, -1 if it did not start
  double wall_time_s = 0;      // from start to exit, measured by the study
  double cpu_time_s = 0;       // user + system time of the run's process (getrusage)
  double peak_memory_mib = 0;  // the run process's maximum resident set size (getrusage)
  int rank = 0;                // the MPI rank that ran it (0 without MPI)
  std::string host;            // the machine it ran on (gethostname)
  std::string reason;          // one line; "" for ok
  std::vector<double> outputs;     // one per study output, NaN when not extracted
  std::vector<std::string> units;  // unit of each output ("" when unknown)
};

// `parameters` ("key=value") are written as comment lines for a person reading a marker.
std::string EncodeRunRecord(const RunRecord& record,
                            const std::vector<std::string>& parameters = {});
// Throws std::runtime_error naming the line for text that is not a complete record.
RunRecord DecodeRunRecord(std::string_view text);

}  // namespace orrery::study
