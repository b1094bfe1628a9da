#include "cli/plot_inputs.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

// A value for a message: at most 60 characters, so that a mutated megabyte line stays readable.
std::string shown(const std::string& text) { return text.size() <= 60 ? text : text.substr(0, 57) + "..."; }

// The cells of a CSV line; "a,b," has three cells (the last empty), unlike std::getline's split.
std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  size_t start = 0;
  for (size_t comma; (comma = line.find(',', start)) != std::string::npos; start = comma + 1)
    out.push_back(line.substr(start, comma - start));
  out.push_back(line.substr(start));
  return out;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

// "`path` line N" (built by append: GCC 12 warns falsely on "`" + string + ...).
std::string line_of(const fs::path& path, long number) {
  std::string out("`");
  out.append(path.string()).append("` line ").append(std::to_string(number));
  return out;
}

}  // namespace

std::optional<double> parse_number(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return std::nullopt;
  const size_t last = text.find_last_not_of(" \t");
  const std::string trimmed = text.substr(first, last - first + 1);
  char* end = nullptr;
  const double value = std::strtod(trimmed.c_str(), &end);           // underflow (subnormals, 0) is a number
  if (end != trimmed.c_str() + trimmed.size()) return std::nullopt;  // also stops at an embedded NUL
  return value;
}

int ResultTable::column(const std::string& name) const {
  for (size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return static_cast<int>(i);
  return -1;
}

int ResultTable::require_column(const std::string& name, const std::string& expected) const {
  const int i = column(name);
  if (i < 0)
    throw BadInput("`" + path.string() + "`: no column `" + name + "` (header `" + shown(joined(columns)) +
                   "`; expected " + expected + ")");
  return i;
}

double ResultTable::metadata_number(const std::string& key, double fallback) const {
  const auto it = metadata.find(key);
  if (it == metadata.end()) return fallback;
  const auto value = parse_number(it->second);
  if (!value || !std::isfinite(*value))
    throw BadInput("`" + path.string() + "`: metadata `" + key + " = " + shown(it->second) + "`: not a finite number");
  return *value;
}

std::string ResultTable::metadata_text(const std::string& key, const std::string& fallback) const {
  const auto it = metadata.find(key);
  return it == metadata.end() ? fallback : it->second;
}

std::string ResultTable::model_label(const std::string& fallback) const {
  return metadata_text("model_label", metadata_text("model", fallback));
}

std::vector<std::string> ResultTable::state_names() const {
  std::vector<std::string> names;
  std::stringstream line(metadata_text("state_names", ""));
  for (std::string name; std::getline(line, name, ',');) names.push_back(name);
  return names;
}

size_t ResultTable::data_rows() const {
  size_t n = 0;
  for (const auto& row : rows) n += !row.empty();
  return n;
}

void ResultTable::require_header(const std::vector<std::string>& expected) const {
  bool ok = columns.size() >= expected.size();
  for (size_t i = 0; ok && i < expected.size(); ++i)
    ok = expected[i] == "X" || expected[i] == "Y" || columns[i] == expected[i];
  if (!ok)
    throw BadInput("`" + path.string() + "`: header `" + shown(joined(columns)) + "`: expected columns " +
                   joined(expected));
}

void ResultTable::require_rows() const {
  if (data_rows() == 0) throw BadInput("`" + path.string() + "`: no data rows (only a header)");
}

void ResultTable::require_grid() const {
  size_t first_size = 0, size = 0, block_start = 0;
  for (size_t i = 0; i <= rows.size(); ++i) {
    if (i < rows.size() && !rows[i].empty()) {
      if (size++ == 0) block_start = i;
      continue;
    }
    if (size == 0) continue;  // (a separator after a separator, or the end after one)
    if (first_size == 0) first_size = size;
    // gnuplot would reject it too, with a message naming neither the file nor the line.
    if (size != first_size)
      throw BadInput(where(block_start) + ": the block of rows starting here has " + std::to_string(size) +
                     " rows, the first has " + std::to_string(first_size) +
                     " (a grid: one block per y value, separated by blank lines, all of one length)");
    size = 0;
  }
}

std::string ResultTable::where(size_t row) const { return line_of(path, row < row_lines.size() ? row_lines[row] : 0); }

ResultTable read_result_table(const fs::path& path, const std::function<bool(const std::string&)>& nan_allowed) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BadInput("cannot read `" + path.string() + "`");
  ResultTable t;
  t.path = path;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("#", 0) == 0) {  // "# key = value" metadata; other comments ("# N: 200") skipped
      const auto eq = line.find(" = ");
      if (line.rfind("# ", 0) == 0 && eq != std::string::npos) t.metadata[line.substr(2, eq - 2)] = line.substr(eq + 3);
      continue;
    }
    if (line.empty()) {
      if (!t.rows.empty() && !t.rows.back().empty()) {
        t.rows.emplace_back();
        t.row_lines.push_back(number);
      }
      continue;
    }
    if (t.columns.empty()) {
      t.columns = cells(line);
      continue;
    }
    const std::vector<std::string> row_cells = cells(line);
    const std::string where = line_of(path, number);
    if (row_cells.size() != t.columns.size())
      throw BadInput(where + ": " + std::to_string(row_cells.size()) + " cells, expected " +
                     std::to_string(t.columns.size()) + " (header `" + shown(joined(t.columns)) + "`)");
    std::vector<double> row;
    for (size_t i = 0; i < row_cells.size(); ++i) {
      const auto value = parse_number(row_cells[i]);
      const std::string cell = where + ", column `" + t.columns[i] + "`: `" + shown(row_cells[i]) + "`";
      if (!value) throw BadInput(cell + " is not a number");
      if (std::isinf(*value)) throw BadInput(cell + " is not a finite number");
      if (std::isnan(*value) && !(nan_allowed && nan_allowed(t.columns[i])))
        throw BadInput(cell + ": nan is allowed only in the result columns of a failed point, not here");
      row.push_back(*value);
    }
    t.rows.push_back(std::move(row));
    t.row_lines.push_back(number);
  }
  if (t.columns.empty()) throw BadInput("`" + path.string() + "`: no header line (expected column names)");
  return t;
}

// ---- JSON ----

void JsonField::fail(const std::string& what) const {
  throw BadInput("`" + file_ + "`: " + (path_.empty() ? std::string("the top level") : "`" + path_ + "`") + ": " +
                 what);
}

void JsonField::require_object() const {
  if (!value_->is_object()) fail("expected an object, found " + std::string(value_->type_name()));
}

JsonField JsonField::at(const std::string& key) const {
  require_object();
  const std::string member = path_.empty() ? key : path_ + "." + key;
  if (!value_->contains(key)) JsonField(*value_, file_, member).fail("missing");
  return JsonField((*value_)[key], file_, member);
}

std::optional<JsonField> JsonField::find(const std::string& key) const {
  require_object();
  if (!value_->contains(key) || (*value_)[key].is_null()) return std::nullopt;
  return at(key);
}

std::vector<JsonField> JsonField::elements() const {
  if (!value_->is_array()) fail("expected a list, found " + std::string(value_->type_name()));
  std::vector<JsonField> out;
  for (size_t i = 0; i < value_->size(); ++i)
    out.emplace_back((*value_)[i], file_, path_ + "[" + std::to_string(i) + "]");
  return out;
}

double JsonField::number() const {
  // The value shown with invalid UTF-8 replaced: dump() would throw on it.
  if (!value_->is_number())
    fail("expected a number, found " + std::string(value_->type_name()) + " " +
         shown(value_->dump(-1, ' ', false, Json::error_handler_t::replace)));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("not a finite number");
  return v;
}

std::string JsonField::text() const {
  if (!value_->is_string()) fail("expected a string, found " + std::string(value_->type_name()));
  return value_->get<std::string>();
}

double JsonField::number_or(const std::string& key, double fallback) const {
  const auto field = find(key);
  return field ? field->number() : fallback;
}

std::string JsonField::text_or(const std::string& key, const std::string& fallback) const {
  const auto field = find(key);
  return field ? field->text() : fallback;
}

Json read_json_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BadInput("cannot read `" + path.string() + "`");
  try {
    return Json::parse(in);
  } catch (const Json::exception& e) {
    throw BadInput("`" + path.string() + "`: not JSON: " + e.what());
  }
}

}  // namespace delayspec::cli
