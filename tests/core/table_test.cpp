#include "granmem/core/table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "temp_dir.hpp"

#include "checks.hpp"

namespace granmem {
namespace {

using testing::error_message;

using Limits = std::numeric_limits<double>;

class TableCsv : public granmem::testing::TempDirTest {};

// Bit-for-bit equality of two doubles, except that any NaN matches any NaN (CSV writes "nan").
::testing::AssertionResult same_double(double expected, double actual) {
  if (std::isnan(expected) && std::isnan(actual)) return ::testing::AssertionSuccess();
  if (std::memcmp(&expected, &actual, sizeof(double)) == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "expected " << expected << " got " << actual;
}

TEST(Table, ColumnsKeepOrderAndReferencesStayValid) {
  Table t;
  Column& a = t.add("a", "mm");
  for (int i = 0; i < 100; ++i)
    t.add("c" + std::to_string(i));
  a.values = {1, 2, 3};  // the reference survives 100 more columns
  EXPECT_EQ(t.rows(), 3u);
  EXPECT_EQ(t["a"].unit, "mm");
  EXPECT_EQ(t["a"].values, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(t.columns().size(), 101u);
  EXPECT_EQ(t.columns()[1].name, "c0");
  EXPECT_TRUE(t.has("c99"));
  EXPECT_FALSE(t.has("c100"));
  EXPECT_THROW(t.add("a"), Error);
  const std::string msg = error_message([&] { (void)t["nope"]; });
  EXPECT_NE(msg.find("'nope'"), std::string::npos) << msg;
}

TEST_F(TableCsv, RoundTripIsExactForRandomAndExtremeDoubles) {
  std::mt19937_64 rng(12345);
  Table t;
  Column& x = t.add("x", "mm");
  Column& frame = t.add("frame", "", true);
  // Any bit pattern: subnormals, huge, negative, NaN payloads, infinities.
  for (int i = 0; i < 3000; ++i) {
    const std::uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    x.values.push_back(v);
  }
  const std::vector<double> special = {0.0,
                                       -0.0,
                                       Limits::denorm_min(),
                                       -Limits::denorm_min(),
                                       Limits::min(),
                                       Limits::max(),
                                       Limits::lowest(),
                                       Limits::epsilon(),
                                       1e-300,
                                       -1.2345678901234567e-310,
                                       0.1,
                                       1.0 / 3.0,
                                       -2.5e300,
                                       Limits::infinity(),
                                       -Limits::infinity(),
                                       Limits::quiet_NaN(),
                                       -Limits::quiet_NaN()};
  x.values.insert(x.values.end(), special.begin(), special.end());
  for (std::uint64_t bits : {0x7ff0000000000001ull, 0xfff8000000000123ull, 0x7fffffffffffffffull}) {
    double nan_with_payload;  // signalling, negative and all-ones NaNs
    std::memcpy(&nan_with_payload, &bits, sizeof bits);
    x.values.push_back(nan_with_payload);
  }
  const std::int64_t big = (std::int64_t{1} << 53) - 1;
  std::uniform_int_distribution<std::int64_t> ints(-big, big);
  for (std::size_t i = 0; i < x.values.size(); ++i)
    frame.values.push_back(double(ints(rng)));
  frame.values[0] = 0;
  frame.values[1] = double(big);
  frame.values[2] = double(-big);
  frame.values[3] = -1;
  frame.values[4] = Limits::quiet_NaN();

  std::size_t nans = 0;
  for (double v : x.values)
    nans += std::isnan(v);
  ASSERT_GE(nans, 5u);

  const auto file = path("t.csv");
  write_csv(t, file, {"unit x: mm", "second comment"});
  const std::string text = read_text(file);
  EXPECT_EQ(text.rfind("# unit x: mm\n# second comment\nx,frame\n", 0), 0u) << text.substr(0, 80);
  // Integer columns are written without fraction or exponent.
  EXPECT_NE(text.find(",9007199254740991\n"), std::string::npos);
  EXPECT_NE(text.find(",-9007199254740991\n"), std::string::npos);

  const CsvColumns back = read_csv(file, {"x", "frame"});
  ASSERT_EQ(back.table.rows(), x.values.size());
  ASSERT_EQ(back.lines.size(), x.values.size());
  EXPECT_EQ(back.lines.front(), 4u);  // two comments, the header, then the first row
  EXPECT_EQ(back.lines.back(), 3u + x.values.size());
  for (std::size_t i = 0; i < x.values.size(); ++i) {
    ASSERT_TRUE(same_double(x.values[i], back.table["x"].values[i])) << "row " << i;
    ASSERT_TRUE(same_double(frame.values[i], back.table["frame"].values[i])) << "row " << i;
  }
}

TEST_F(TableCsv, CommentsBlankLinesAndUnrequestedColumnsAreSkipped) {
  const auto file = path("in.csv");
  write_text(file,
             "# produced by hand\n"
             "\n"
             ",frame,name,x,notes\n"
             "0,1,alpha,0.5,text with spaces\n"
             "# a comment between rows\n"
             "1, +2 ,beta,\"-3e2\",x\r\n"
             "\n"
             "2,3,gamma,,nan?\n"
             "3,4,delta,nan,\n");
  const CsvColumns c = read_csv(file, {"x", "frame"}, {"radius", "name_missing"});
  ASSERT_EQ(c.table.columns().size(), 2u);
  EXPECT_EQ(c.table.columns()[0].name, "x");  // in the order asked for
  EXPECT_EQ(c.table.columns()[1].name, "frame");
  EXPECT_FALSE(c.table.has("radius"));
  EXPECT_FALSE(c.table.has("name"));
  EXPECT_EQ(c.table["frame"].values, (std::vector<double>{1, 2, 3, 4}));
  const auto& x = c.table["x"].values;
  ASSERT_EQ(x.size(), 4u);
  EXPECT_EQ(x[0], 0.5);
  EXPECT_EQ(x[1], -300.0);
  EXPECT_TRUE(std::isnan(x[2]));  // empty field
  EXPECT_TRUE(std::isnan(x[3]));  // "nan"
  EXPECT_EQ(c.lines, (std::vector<std::size_t>{4, 6, 8, 9}));
}

// Lines ending in a lone CR (classic Mac OS, some instruments' software) and quoted fields
// holding commas and quotes (RFC 4180, as spreadsheets write text).
TEST_F(TableCsv, LoneCarriageReturnsAndQuotedCommasAreRead) {
  const auto file = path("mac.csv");
  write_text(file, "frame,name,x\r0,\"grain, \"\"big\"\"\",1.5\r1,plain,2.5\r\r2,\"\",3.5");
  const CsvColumns c = read_csv(file, {"frame", "x"});
  EXPECT_EQ(c.table["frame"].values, (std::vector<double>{0, 1, 2}));
  EXPECT_EQ(c.table["x"].values, (std::vector<double>{1.5, 2.5, 3.5}));
  EXPECT_EQ(c.lines, (std::vector<std::size_t>{2, 3, 5}));
}

TEST_F(TableCsv, ExcelByteOrderMarkIsSkipped) {
  // Excel's "CSV UTF-8" starts the file with EF BB BF, before the header or a comment.
  const auto file = path("excel.csv");
  write_text(file,
             "\xEF\xBB\xBF"
             "frame,x\n0,1.5\n");
  EXPECT_EQ(read_csv(file, {"frame", "x"}).table["x"].values, (std::vector<double>{1.5}));
  write_text(file,
             "\xEF\xBB\xBF"
             "# made in Excel\nframe,x\n0,2.5\n");
  EXPECT_EQ(read_csv(file, {"frame", "x"}).table["x"].values, (std::vector<double>{2.5}));
}

TEST_F(TableCsv, MissingRequiredColumnIsNamed) {
  const auto file = path("in.csv");
  write_text(file, "frame,x,y\n1,2,3\n");
  const std::string msg = error_message([&] { read_csv(file, {"frame", "x", "z"}, {"y"}); });
  EXPECT_NE(msg.find("'z'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
  // An optional column may be missing.
  EXPECT_NO_THROW(read_csv(file, {"frame"}, {"z"}));
}

TEST_F(TableCsv, NonNumericFieldNamesLineAndColumn) {
  const auto file = path("in.csv");
  write_text(file, "# c\nframe,x,y\n1,2,3\n2,abc,4\n");
  const std::string msg = error_message([&] { read_csv(file, {"frame", "x", "y"}); });
  EXPECT_NE(msg.find(file.string() + " line 4, column 'x'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'abc'"), std::string::npos) << msg;
  // The same bad field in a column not asked for is never read.
  EXPECT_NO_THROW(read_csv(file, {"frame", "y"}));
  // A number followed by junk and an out-of-range number are not numbers either.
  write_text(file, "x\n1.5mm\n");
  EXPECT_NE(error_message([&] { read_csv(file, {"x"}); }).find("line 2, column 'x'"),
            std::string::npos);
  write_text(file, "x\n1\n1e999\n");
  EXPECT_NE(error_message([&] { read_csv(file, {"x"}); }).find("line 3, column 'x'"),
            std::string::npos);
}

TEST_F(TableCsv, WrongFieldCountNamesTheLine) {
  const auto file = path("in.csv");
  write_text(file, "frame,x,y\n1,2,3\n2,3\n");
  const std::string msg = error_message([&] { read_csv(file, {"frame"}); });
  EXPECT_NE(msg.find(file.string() + " line 3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("2 fields, expected 3"), std::string::npos) << msg;
  write_text(file, "frame,x,y\n1,2,3,4\n");
  EXPECT_NE(error_message([&] { read_csv(file, {"frame"}); }).find(" line 2"), std::string::npos);
}

TEST_F(TableCsv, EmptyOrMissingFileAndDuplicateHeaderAreErrors) {
  const auto file = path("in.csv");
  write_text(file, "# only a comment\n\n");
  EXPECT_THROW(read_csv(file, {"x"}), Error);
  write_text(file, "x,y,x\n1,2,3\n");
  EXPECT_NE(error_message([&] { read_csv(file, {"y"}); }).find("'x'"), std::string::npos);
  const std::string msg = error_message([&] { read_csv(path("absent.csv"), {"x"}); });
  EXPECT_NE(msg.find("absent.csv"), std::string::npos) << msg;
  // Header only: no rows, but the columns are there.
  write_text(file, "x,y\n");
  const CsvColumns c = read_csv(file, {"x"});
  EXPECT_EQ(c.table.rows(), 0u);
  EXPECT_TRUE(c.table.has("x"));
}

TEST_F(TableCsv, WriteToMissingFolderIsAnError) {
  Table t;
  t.add("x").values = {1};
  EXPECT_THROW(write_csv(t, path("no/such/folder/t.csv")), Error);
}

}  // namespace
}  // namespace granmem
