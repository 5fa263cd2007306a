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

}  // namespace poundsim::io
