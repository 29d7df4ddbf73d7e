// Text from files as the harness prints it (io/text.hpp): escaped for a
// terminal, and for Markdown, where a name from a hand-edited results file
// must neither break a table nor hide the text around it.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/files.hpp"
#include "io/text.hpp"
#include "studies/study.hpp"

namespace idcol::harness {
namespace {

using nlohmann::json;

TEST(Text, EscapesWhatBreaksOrHidesText) {
  EXPECT_EQ(escaped("Poly-Ellip 1e-3 (cut)"), "Poly-Ellip 1e-3 (cut)");
  EXPECT_EQ(escaped("a\nb\tc\rd"), "a\\nb\\tc\\rd");
  EXPECT_EQ(escaped(std::string("a\0b", 3)), "a\\x00b");
  EXPECT_EQ(escaped("\x1b[31mred\x7f"), "\\x1B[31mred\\x7F");
  EXPECT_EQ(escaped("back\\slash"), "back\\\\slash");
  // U+202E (right-to-left override), U+2066 (isolate), U+200B (zero width),
  // U+2028 (line separator), U+FEFF, a C1 control (U+009B, the CSI of
  // 8-bit terminals), a tag character (U+E0041).
  EXPECT_EQ(escaped("a\u202Eb\u2066c\u200Bd\u2028e\uFEFFf\u009Bg\U000E0041h"),
            "a\\u202Eb\\u2066c\\u200Bd\\u2028e\\uFEFFf\\u009Bg\\U000E0041h");
  // Printable UTF-8 stays; bytes that are not UTF-8 (stray, truncated,
  // overlong, a surrogate) are shown byte by byte.
  EXPECT_EQ(escaped("W\u00fcrfel \u03b2 \u6f22"), "W\u00fcrfel \u03b2 \u6f22");
  EXPECT_EQ(escaped("\x80x\xe2\x80y\xc0\xafz\xed\xa0\x80"), "\\x80x\\xE2\\x80y\\xC0\\xAFz\\xED\\xA0\\x80");
  EXPECT_EQ(md_text("a|b<i>c\\d\ne"), "a\\|b&lt;i>c\\\\d\\ne");
  EXPECT_EQ(md_text("x < 1, a<b, </i>, <!--, <?"), "x < 1, a&lt;b, &lt;/i>, &lt;!--, &lt;?");
  EXPECT_EQ(md_code("-O3 -march=native"), "`-O3 -march=native`");
  EXPECT_EQ(md_code("a`b|c\\d"), "``a`b\\|c\\d``");
  EXPECT_EQ(md_code("`x``"), "``` `x`` ```");
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  for (std::size_t at = 0, end; at < s.size(); at = end + 1) {
    end = s.find('\n', at);
    if (end == std::string::npos) end = s.size();
    out.push_back(s.substr(at, end - at));
  }
  return out;
}

/// The '|' of a Markdown line that separate cells (not those escaped as \|).
int cell_bars(const std::string& line) {
  int n = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == '\\') ++i;
    else if (line[i] == '|') ++n;
  }
  return n;
}

// The Markdown of a results file whose scene name, entry names and CPU were
// edited by hand to hold a newline, '|', a right-to-left override, a
// terminal escape, an HTML tag and a backtick: every line and every table
// cell of the unedited file's Markdown is still there, and none of those
// characters is written raw (they were: the scene name's newline ended the
// title, its '|' made a table's row one cell longer).
TEST(Text, MarkdownOfAHandEditedResultsFileKeepsItsLinesAndCells) {
  const std::string hostile = "x\n| y\u202Ez\x1b[31m<b>`q\\";
  const std::string baseline = std::string(IDCOL_CONFIGS_DIR) + "/../results/baseline/";
  for (const char* file : {"ci.json", "stress.json", "ci_toi.json"}) {
    const json clean = read_json_file(baseline + file);
    json edited = clean;
    edited["scene"]["name"] = hostile;
    edited["metadata"]["cpu_model"] = hostile;
    if (edited.contains("pairs")) edited["pairs"][0]["body1"] = hostile;
    if (edited.contains("cases")) edited["cases"][0]["name"] = hostile;
    if (edited.contains("toi_pairs")) edited["toi_pairs"][0]["name"] = hostile;
    const StudyKind& kind = *study_kind_of_schema(clean.at("schema").get<std::string>());
    const std::vector<std::string> before = lines_of(kind.table(clean, file)), after = lines_of(kind.table(edited, file));
    ASSERT_EQ(after.size(), before.size()) << file;
    for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(cell_bars(after[i]), cell_bars(before[i])) << file << ": " << after[i];
    const std::string md = kind.table(edited, file);
    for (const char* raw : {"\u202E", "\x1b", "<b>", "x\n"}) EXPECT_EQ(md.find(raw), std::string::npos) << file << ": " << raw;
    EXPECT_NE(md.find("x\\n\\| y\\u202Ez\\x1B[31m&lt;b>`q\\\\"), std::string::npos) << file;
  }
}

}  // namespace
}  // namespace idcol::harness
