#include "poundsim/io/table.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace poundsim::io {

void write_csv(OutputFile& out, const Table& table) {
  const std::size_t rows = table.rows();
  CsvWriter csv(out);
  for (const TableColumn& c : table.columns()) {
    if (c.size() != rows) {
      throw std::logic_error(fmt::format("table column {} has {} rows, the table {}", c.name, c.size(), rows));
    }
    csv.text(c.name);
  }
  csv.end_row();
  for (std::size_t r = 0; r < rows; ++r) {
    for (const TableColumn& c : table.columns()) {
      if (const auto* numbers = std::get_if<TableColumn::Numbers>(&c.values)) {
        const double x = (*numbers)[r];
        if (std::isnan(x)) {
          csv.empty();
        } else {
          csv.number(x);
        }
      } else if (const auto* integers = std::get_if<TableColumn::Integers>(&c.values)) {
        csv.integer((*integers)[r]);
      } else {
        csv.text(std::get<TableColumn::Texts>(c.values)[r]);
      }
    }
    csv.end_row();
  }
}

nlohmann::ordered_json csv_metadata(std::string_view file, std::span<const CsvColumn> columns) {
  nlohmann::ordered_json declared = nlohmann::ordered_json::array();
  for (const CsvColumn& c : columns) {
    declared.push_back({{"titles", c.title}, {"datatype", c.datatype}, {"schema:unitText", c.unit}});
  }
  return {{"@context", "http://www.w3.org/ns/csvw"}, {"url", file}, {"tableSchema", {{"columns", declared}}}};
}

void write_csv_metadata(OutputTransaction& out, const std::string& file, std::span<const CsvColumn> columns) {
  OutputFile& f = out.open(file + "-metadata.json");
  f.text(csv_metadata(file, columns).dump(2));
  f.character('\n');
}

std::vector<CsvColumn> csv_columns(const Table& table) {
  std::vector<CsvColumn> columns;
  for (const TableColumn& c : table.columns()) {
    const std::string_view datatype = std::holds_alternative<TableColumn::Numbers>(c.values)    ? "number"
                                      : std::holds_alternative<TableColumn::Integers>(c.values) ? "integer"
                                                                                                : "string";
    columns.push_back({c.name, c.unit, datatype});
  }
  return columns;
}

void write_table(OutputTransaction& out, const std::string& file, const Table& table) {
  write_csv(out.open(file), table);
  write_csv_metadata(out, file, csv_columns(table));
}

}  // namespace poundsim::io
