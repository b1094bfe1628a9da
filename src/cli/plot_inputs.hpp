#pragma once
// The result files `delayspec plot` reads (docs/formats.md), read strictly. A file of the wrong
// shape is bad input (BadInput, exit 2) naming the file, the line or field, and the value: a
// short or long CSV row, a cell that is not a number, a metadata value that should be a number,
// a JSON field that is missing or of the wrong type. Values leave here as checked numbers; the
// only text that leaves (names, labels) must reach a gnuplot script through gnuplot_string()
// (gnuplot_script.hpp), never pasted.
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace delayspec::cli {

// `text` as a number, or nothing when it is not one. The whole text must be the number
// (surrounding blanks allowed); decimal and hexadecimal floats ("0x1.428f5c28f5c29p+0", as a run
// writes at full precision) and "nan" parse; "inf" and overflow give an infinite value.
std::optional<double> parse_number(const std::string& text);

// A CSV table of delayspec: "# key = value" metadata lines, a header line of column names, rows
// of numbers; blank lines (grid-block separators) kept as empty rows.
struct ResultTable {
  std::filesystem::path path;
  std::map<std::string, std::string> metadata;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;  // every non-empty row has columns.size() cells
  std::vector<long> row_lines;            // the line number of each row in the file

  // "`path` line L" of a row, for messages.
  std::string where(size_t row) const;

  // The index of a column; -1 when absent.
  int column(const std::string& name) const;
  // The index of a column; BadInput naming the file and the expected columns when absent.
  int require_column(const std::string& name, const std::string& expected) const;
  // A metadata value as a finite number; `fallback` when the key is absent; BadInput naming the
  // file, the key and the value when it is not a finite number.
  double metadata_number(const std::string& key, double fallback) const;
  // A metadata value as text (unchecked: quote it with gnuplot_string()).
  std::string metadata_text(const std::string& key, const std::string& fallback) const;
  // The model as titles name it: the `# model_label` line (an [equations] model by its scene),
  // else the key `model`, else `fallback`.
  std::string model_label(const std::string& fallback) const;
  // The state's names of the `# state_names = x,v` line (the model's, in order), empty without one.
  std::vector<std::string> state_names() const;
  // The number of non-empty rows.
  size_t data_rows() const;

  // Shape checks of a figure's input, BadInput naming the file (and line) when they fail:
  // the header starts with `expected` ("X", "Y" stand for any name);
  void require_header(const std::vector<std::string>& expected) const;
  // there is at least one row to draw;
  void require_rows() const;
  // the rows are a grid (chart, basin: gnuplot's image): one block per y value, separated by
  // blank lines, every block as long as the first.
  void require_grid() const;
};

// Reads a CSV table. Every row must have as many cells as the header and every cell must be a
// finite number, except that a column for which `nan_allowed(name)` holds may hold "nan" (the
// formats write it for the results of failed points); anything else is BadInput naming the file,
// the line, the column and the cell.
ResultTable read_result_table(const std::filesystem::path& path,
                              const std::function<bool(const std::string&)>& nan_allowed = nullptr);

// A JSON value of a result file with typed access: a missing field or a wrong type is BadInput
// naming the file and the field's path (e.g. "`converge.json`: `rows[2].error`: ...").
class JsonField {
 public:
  JsonField(const nlohmann::json& value, std::string file, std::string path)
      : value_(&value), file_(std::move(file)), path_(std::move(path)) {}

  // A member that must be present (this must be an object).
  JsonField at(const std::string& key) const;
  // A member when present and not null; nothing otherwise (this must be an object).
  std::optional<JsonField> find(const std::string& key) const;
  // The elements of an array.
  std::vector<JsonField> elements() const;
  // A finite number.
  double number() const;
  // A string.
  std::string text() const;

  // Optional members with a fallback when absent or null; present with the wrong type: BadInput.
  double number_or(const std::string& key, double fallback) const;
  std::string text_or(const std::string& key, const std::string& fallback) const;

  bool is_null() const { return value_->is_null(); }
  bool is_array() const { return value_->is_array(); }
  bool is_number() const { return value_->is_number(); }
  const std::string& path() const { return path_; }
  // BadInput "`file`: `path`: what".
  [[noreturn]] void fail(const std::string& what) const;

 private:
  void require_object() const;
  const nlohmann::json* value_;
  std::string file_, path_;
};

// Parses a JSON result file; BadInput when it cannot be read or is not JSON. The document is
// kept by the caller; JsonField(document, file name, "") then reads it.
nlohmann::json read_json_file(const std::filesystem::path& path);

}  // namespace delayspec::cli
