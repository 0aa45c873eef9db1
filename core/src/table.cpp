#include "granmem/core/table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"

namespace granmem {

Column& Table::add(std::string name, std::string unit, bool integer) {
  if (has(name)) throw Error("table already has a column '" + name + "'");
  columns_.push_back(Column{std::move(name), std::move(unit), integer, {}});
  return columns_.back();
}

bool Table::has(std::string_view name) const {
  return std::any_of(columns_.begin(), columns_.end(),
                     [&](const Column& c) { return c.name == name; });
}

const Column& Table::operator[](std::string_view name) const {
  for (const Column& c : columns_) {
    if (c.name == name) return c;
  }
  throw Error("table has no column '" + std::string(name) + "'");
}

Column& Table::operator[](std::string_view name) {
  return const_cast<Column&>(static_cast<const Table&>(*this)[name]);
}

std::size_t Table::rows() const {
  return columns_.empty() ? 0 : columns_.front().values.size();
}

namespace {

void append_number(std::string& out, double v, bool integer) {
  if (std::isnan(v)) {
    out += "nan";
    return;
  }
  char buf[32];
  const auto [end, ec] = integer && std::abs(v) < 9.007199254740992e15
                             ? std::to_chars(buf, buf + sizeof buf, static_cast<long long>(v))
                             : std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  out.append(buf, end);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

// Splits one CSV line on commas; a field in double quotes (RFC 4180) may hold commas and
// doubled quotes, and is given without its quotes.
// Fields between `delimiter`s; a quoted field (RFC 4180) may hold delimiters and is given
// without its quotes (a doubled quote inside stays doubled).
void split(std::string_view line, std::vector<std::string_view>& fields, char delimiter) {
  fields.clear();
  std::size_t start = 0;
  while (true) {
    std::size_t text = line.find_first_not_of(" \t", start);
    std::size_t open = std::string_view::npos, close = std::string_view::npos;
    if (text != std::string_view::npos && line[text] == '"') {
      open = text;
      for (++text; text < line.size(); ++text) {  // to the closing quote
        if (line[text] != '"') continue;
        if (text + 1 < line.size() && line[text + 1] == '"') {
          ++text;
        } else {
          close = text;
          break;
        }
      }
    } else {
      text = start;
    }
    const std::size_t end = line.find(delimiter, std::min(text, line.size()));
    std::string_view field = trim(line.substr(start, end - start));
    if (close != std::string_view::npos && field.size() == close - open + 1) {
      field = line.substr(open + 1, close - open - 1);
    }
    fields.push_back(field);
    if (end == std::string_view::npos) return;
    start = end + 1;
  }
}

std::optional<double> parse_number(std::string_view field) {
  if (field.empty()) return std::numeric_limits<double>::quiet_NaN();
  const char* begin = field.data();
  const char* last = field.data() + field.size();
  if (*begin == '+') ++begin;
  double v = 0;
  const auto [end, ec] = std::from_chars(begin, last, v);
  if (ec == std::errc::result_out_of_range) return std::nullopt;
  if (ec != std::errc() || end != last) return std::nullopt;
  return v;
}

}  // namespace

void write_csv(const Table& table, const std::filesystem::path& path,
               const std::vector<std::string>& comment) {
  AtomicFile file(path);  // a failed write leaves any earlier table in place
  write_csv(table, file, comment);
  file.commit();
}

std::string csv_header(const Table& table, const std::vector<std::string>& comment) {
  std::string text;
  for (const std::string& line : comment)
    text += "# " + line + "\n";
  const auto& cols = table.columns();
  for (std::size_t c = 0; c < cols.size(); ++c)
    text += (c ? "," : "") + cols[c].name;
  return text + '\n';
}

void write_csv_rows(const Table& table, std::ostream& out) {
  const auto& cols = table.columns();
  std::string text;
  for (std::size_t r = 0; r < table.rows(); ++r) {
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (c) text += ',';
      append_number(text, cols[c].values[r], cols[c].integer);
    }
    text += '\n';
    if (text.size() > (1u << 20)) {
      out << text;
      text.clear();
    }
  }
  out << text;
}

void write_csv(const Table& table, AtomicFile& file, const std::vector<std::string>& comment) {
  const std::filesystem::path& path = file.target();
  std::ofstream out(file.temp_path(), std::ios::binary);
  if (!out) throw Error(path.string() + ": cannot open for writing");
  out << csv_header(table, comment);
  write_csv_rows(table, out);
  out.close();
  if (!out) throw Error(path.string() + ": write failed (disk full?)");
}

CsvColumns read_csv(const std::filesystem::path& path, const std::vector<std::string>& required,
                    const std::vector<std::string>& optional, const CsvReadOptions& options) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw Error(path.string() + ": cannot open for reading");
  const std::string where = path.string();
  // Lines may end in LF, CRLF or a lone CR (classic Mac OS, some instrument software).
  std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  for (std::size_t k = 0; (k = text.find('\r', k)) != std::string::npos; ++k) {
    if (k + 1 == text.size() || text[k + 1] != '\n') text[k] = '\n';
  }
  std::istringstream in(std::move(text));

  std::string line;
  std::size_t line_no = 0;
  std::vector<std::string_view> fields;
  // Header: the first line that is not a comment or blank.
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // Excel's BOM
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    have_header = true;
    break;
  }
  if (!have_header) throw Error(where + ": empty file, expected a CSV header line");
  // Tab-separated when the header has tabs and no comma (a TSV, or a spreadsheet's copy).
  const char delimiter =
      line.find('\t') != std::string::npos && line.find(',') == std::string::npos ? '\t' : ',';
  std::vector<std::string> header;
  split(line, fields, delimiter);
  for (std::string_view f : fields) {
    std::string name(f);
    if (const auto renamed = options.rename.find(name); renamed != options.rename.end()) {
      name = renamed->second;
    }
    if (!name.empty() && std::find(header.begin(), header.end(), name) != header.end()) {
      throw Error(where + ": column '" + name + "' appears twice in the header");
    }
    header.push_back(name);
  }

  CsvColumns result;
  std::vector<std::pair<std::size_t, Column*>> wanted;  // file field index, column
  auto want = [&](const std::string& name, bool must) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) {
      if (!must) return;
      std::string have;
      for (const std::string& h : header)
        have += (have.empty() ? "" : ", ") + h;
      throw Error(where + ": missing required column '" + name + "' (header has: " + have + ")");
    }
    wanted.emplace_back(static_cast<std::size_t>(it - header.begin()), &result.table.add(name));
  };
  for (const std::string& name : required)
    want(name, true);
  for (const std::string& name : optional)
    want(name, false);

  for (std::size_t skipped = 0; skipped < options.skip_rows && std::getline(in, line); ++skipped)
    ++line_no;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = trim(line);
    if (t.empty() || t.front() == '#') continue;
    split(line, fields, delimiter);
    if (fields.size() != header.size()) {
      throw Error(where + " line " + std::to_string(line_no) + ": " +
                  std::to_string(fields.size()) + " fields, expected " +
                  std::to_string(header.size()) + " as in the header");
    }
    for (auto& [index, column] : wanted) {
      const std::optional<double> v = parse_number(fields[index]);
      if (!v) {
        throw Error(where + " line " + std::to_string(line_no) + ", column '" + column->name +
                    "': expected a number, found '" + std::string(fields[index]) + "'");
      }
      column->values.push_back(*v);
    }
    result.lines.push_back(line_no);
  }
  if (in.bad()) throw Error(where + ": read error");
  return result;
}

}  // namespace granmem
