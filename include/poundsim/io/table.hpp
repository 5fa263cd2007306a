#pragma once
/// @file
/// A table of results declared once, column by column: the CSV files poundsim writes
/// (frf.csv, study.csv, ensemble.csv, evaluations.csv) are written from it (write_csv), and the
/// Python module hands its columns to NumPy without going through text (docs/python.md).
///
/// A column holds numbers (a missing one is NaN, written as an empty field: no NaN is ever
/// written), whole numbers or text, with its unit ("1" for a ratio, "" for text).

#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/io/output_files.hpp"

namespace poundsim::io {

struct TableColumn {
  using Numbers = std::vector<double>;
  using Integers = std::vector<std::int64_t>;
  using Texts = std::vector<std::string>;
  std::string name;
  std::string unit;
  std::variant<Numbers, Integers, Texts> values;

  [[nodiscard]] std::size_t size() const {
    return std::visit([](const auto& v) { return v.size(); }, values);
  }
};

class Table {
 public:
  /// Adds a column (of `rows()` values once the table has one) and returns it to fill; it stays
  /// valid while columns are added after it.
  template <typename Values>
  Values& add(std::string name, std::string unit) {
    columns_.push_back({std::move(name), std::move(unit), Values{}});
    return std::get<Values>(columns_.back().values);
  }
  TableColumn::Numbers& numbers(std::string name, std::string unit) {
    return add<TableColumn::Numbers>(std::move(name), std::move(unit));
  }
  TableColumn::Integers& integers(std::string name, std::string unit = "") {
    return add<TableColumn::Integers>(std::move(name), std::move(unit));
  }
  TableColumn::Texts& texts(std::string name) { return add<TableColumn::Texts>(std::move(name), ""); }

  [[nodiscard]] const std::deque<TableColumn>& columns() const { return columns_; }
  [[nodiscard]] std::deque<TableColumn>& columns() { return columns_; }
  /// The rows (of the first column; every column has as many).
  [[nodiscard]] std::size_t rows() const { return columns_.empty() ? 0 : columns_.front().size(); }

 private:
  std::deque<TableColumn> columns_;  // a deque: add()'s references stay valid
};

/// Writes `table` as CSV (CsvWriter's rules): a header of the column names, then one row per
/// row. Throws std::logic_error when the columns differ in length.
void write_csv(OutputFile& out, const Table& table);

/// A CSV column as its metadata declares it: the header's text, its unit ("1" a ratio, "" text
/// or a count) and its datatype ("number", "integer" or "string").
struct CsvColumn {
  std::string title;
  std::string unit;
  std::string_view datatype = "number";
};

/// The metadata of the CSV file `file` (its name in the folder), in the W3C "CSV on the Web"
/// form a reader finds by name beside it (`<file>-metadata.json`): the columns in order, each
/// with its title, datatype and unit (schema:unitText). Units travel here, not in names.
[[nodiscard]] nlohmann::ordered_json csv_metadata(std::string_view file, std::span<const CsvColumn> columns);

/// Writes csv_metadata(file, columns) as `<file>-metadata.json` in `out`.
void write_csv_metadata(OutputTransaction& out, const std::string& file, std::span<const CsvColumn> columns);

/// The columns of `table` as its metadata declares them.
[[nodiscard]] std::vector<CsvColumn> csv_columns(const Table& table);

/// Writes `table` as `file` in `out` (write_csv) and its metadata beside it (csv_metadata).
void write_table(OutputTransaction& out, const std::string& file, const Table& table);

}  // namespace poundsim::io
