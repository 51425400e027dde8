#include "tools/cli/inspect_command.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <vector>

#include "mbd/hdf5_reader.h"
#include "tools/cli/error_message.h"

namespace orrery::cli {
namespace {

using Entry = Hdf5Reader::Entry;

// Depth of an entry below the root ("/" is 0, "/bodies" 1, "/bodies/bob" 2)
int Depth(const std::string& path) {
  if (path == "/") return 0;
  return static_cast<int>(std::count(path.begin(), path.end(), '/'));
}

// The last component of a path, with "/" appended for groups
std::string Label(const Entry& e) {
  if (e.path == "/") return "/";
  return e.path.substr(e.path.rfind('/') + 1) + (e.is_group ? "/" : "");
}

std::string Shape(const std::vector<std::int64_t>& shape) {
  if (shape.empty()) return "scalar";
  std::string text;
  for (std::size_t i = 0; i < shape.size(); ++i) text += (i ? " x " : "") + std::to_string(shape[i]);
  return text;
}

// "key=value" for every attribute but `skip`, comma separated
std::string AttributeList(const Entry& e, const std::string& skip) {
  std::string text;
  for (const auto& [key, value] : e.attributes) {
    if (key == skip) continue;
    text += (text.empty() ? "" : ", ") + key + "=" + AttributeSummary(value, 48);
  }
  return text;
}

std::string Attribute(const Entry& e, const std::string& key) {
  for (const auto& [k, value] : e.attributes)
    if (k == key) return value;
  return "";
}

std::string Padded(const std::string& text, std::size_t width) {
  return text.size() >= width ? text + " " : text + std::string(width - text.size(), ' ');
}

void PrintListing(std::ostream& out, const std::string& path, const std::vector<Entry>& entries) {
  // File attributes, keys aligned
  out << "file " << path << '\n';
  std::size_t key_width = 0;
  const Entry* root = nullptr;
  for (const Entry& e : entries)
    if (e.path == "/") root = &e;
  if (root) {
    for (const auto& attribute : root->attributes) key_width = std::max(key_width, attribute.first.size());
    for (const auto& [key, value] : root->attributes)
      out << "  " << Padded(key, key_width + 2) << AttributeSummary(value) << '\n';
  }

  // Tree: names indented by depth, then shape, unit and other attributes in aligned columns
  std::size_t name_width = 0, shape_width = 0, unit_width = 0;
  for (const Entry& e : entries) {
    name_width = std::max(name_width, 2 * Depth(e.path) + Label(e).size());
    if (e.is_group) continue;
    shape_width = std::max(shape_width, Shape(e.shape).size());
    unit_width = std::max(unit_width, Attribute(e, "unit").size());
  }
  out << '\n';
  for (const Entry& e : entries) {
    std::string line = std::string(2 * Depth(e.path), ' ') + Label(e);
    if (e.is_group) {
      if (e.path != "/") {
        const std::string attributes = AttributeList(e, "");
        if (!attributes.empty()) line = Padded(line, name_width + 2) + attributes;
      }
    } else {
      const std::string unit = Attribute(e, "unit");
      line = Padded(line, name_width + 2) + Padded(Shape(e.shape), shape_width + 2) +
             Padded(unit.empty() ? std::string("-") : unit, unit_width + 2) + AttributeList(e, "unit");
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << '\n';
  }
  out << std::flush;
}

}  // namespace

std::string AttributeSummary(const std::string& value, std::size_t max_chars) {
  // Count the lines (a trailing line break does not start a line)
  std::size_t lines = std::count(value.begin(), value.end(), '\n');
  if (!value.empty() && value.back() != '\n') ++lines;
  std::string text = value.substr(0, value.find('\n'));
  if (text.size() > max_chars) text = text.substr(0, max_chars > 3 ? max_chars - 3 : 0) + "...";
  if (lines > 1) text += "  (" + std::to_string(lines) + " lines)";
  return text;
}

int InspectCommand(const InspectArgs& args, std::ostream& out, std::ostream& err) {
  std::vector<Entry> entries;
  try {
    const Hdf5Reader reader(args.path);
    entries = reader.List();
  } catch (const std::exception& e) {
    ReportError(err, e.what());
    return kExitFailure;
  }
  PrintListing(out, args.path, entries);
  return kExitSuccess;
}

}  // namespace orrery::cli
