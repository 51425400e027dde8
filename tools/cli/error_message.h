#pragma once
// One-line error messages of the `orrery` command-line program.
//
// Every failure of a command ends in exactly one line on the error stream,
// "orrery: error: <reason>", whatever the reason's origin (a scene file, HDF5, SUNDIALS, CLI11):
// scripts and CI logs can grep it, and no stack trace or multi-line dump reaches the user.
//
// Usage:
//   catch (const std::exception& e) { ReportError(err, e.what()); return kExitFailure; }
#include <ostream>
#include <string>
#include <string_view>

namespace orrery::cli {

// Exit codes of the commands: 0 success, 1 runtime failure, 2 bad usage (CLI11), 128 + signal
// number when interrupted (130 for SIGINT, 143 for SIGTERM), as shells report them.
inline constexpr int kExitSuccess = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitSignalBase = 128;

// `text` folded onto one line: line breaks and tabs become spaces, runs of spaces collapse,
// leading and trailing blanks go; control bytes (ESC, BEL, NUL, ...) and bytes that are not
// UTF-8 become "\xNN", so that no file content a message quotes can drive the terminal. An
// empty result becomes "unknown error".
std::string OneLine(std::string_view text);

// OneLine(text), cut after max_chars characters with "... (N more characters)" (a message that
// quotes a file never floods the terminal).
std::string Sanitized(std::string_view text, std::size_t max_chars = 600);

// Writes "orrery: error: " + Sanitized(reason) + "\n" to `err` and flushes it.
void ReportError(std::ostream& err, std::string_view reason);

}  // namespace orrery::cli
