#pragma once

#include <cstddef>
#include <deque>
#include <filesystem>
#include <map>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "granmem/core/atomic_file.hpp"

namespace granmem {

// One named column of a long-form table. Integer columns (frame, particle, counts) are
// held as doubles (exact up to 2^53) and written without a fraction.
struct Column {
  std::string name;
  std::string unit;  // "" for dimensionless or counts
  bool integer = false;
  std::vector<double> values;
};

// A long-form table with stable column names: one row per grain per frame, the shape
// trackpy and pandas users already work with. The same table goes to CSV and to HDF5.
class Table {
 public:
  // The returned reference stays valid as more columns are added.
  Column& add(std::string name, std::string unit = "", bool integer = false);
  bool has(std::string_view name) const;
  const Column& operator[](std::string_view name) const;  // throws Error if absent
  Column& operator[](std::string_view name);
  std::size_t rows() const;  // rows of the first column (all have the same length)

  const std::deque<Column>& columns() const { return columns_; }

 private:
  std::deque<Column> columns_;
};

// Writes `table` as CSV to `path`. Lines of `comment` are written first, each after "# ".
// Numbers use the shortest text that reads back to the same double; NaN is "nan".
void write_csv(const Table& table, const std::filesystem::path& path,
               const std::vector<std::string>& comment = {});
// The same into `file`'s temporary, for outputs committed together; messages name its
// target.
void write_csv(const Table& table, AtomicFile& file, const std::vector<std::string>& comment = {});
// The pieces of write_csv for a table written in parts (frame by frame): the comment lines
// and the column names, then the rows.
std::string csv_header(const Table& table, const std::vector<std::string>& comment = {});
void write_csv_rows(const Table& table, std::ostream& out);

// A numeric CSV read for some of its columns, with the file line of each row for messages.
struct CsvColumns {
  Table table;                     // the columns asked for that the file has
  std::vector<std::size_t> lines;  // file line (1-based) of each row
};

// How to read another program's table: TrackMate's or a MATLAB script's column names mapped
// onto granmem's, and the rows of text some programs put under the header.
struct CsvReadOptions {
  std::map<std::string, std::string> rename;  // the file's column name -> the name asked for
  std::size_t skip_rows = 0;  // lines after the header that are not data (TrackMate: 3)
};

// Reads a CSV (RFC 4180: quoted fields, CRLF, a BOM) or, when the header has tabs and no
// comma, a TSV, with a header row; lines starting with '#' are comments, columns not asked
// for are skipped unread (a pandas index or text columns are fine). Empty fields and "nan"
// read as NaN. Throws Error naming file, line and column for a missing required column or
// a field that is not a number.
CsvColumns read_csv(const std::filesystem::path& path, const std::vector<std::string>& required,
                    const std::vector<std::string>& optional = {},
                    const CsvReadOptions& options = {});

}  // namespace granmem
