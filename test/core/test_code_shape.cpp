// The shape of the project's own code: no function of the library, the tools or the ROS layer is
// longer than kMaxFunctionLines lines, so that each one can be read at once.
//
// The scan matches braces over the text with comments, string and character literals (raw ones
// too) and preprocessor lines blanked out. A `{` opens a function body when it follows, at
// namespace or class scope, a declaration with a parameter list: column-0 definitions, member
// functions defined in a class body at any indentation, constructors with initializer lists. It
// does not see: code generated at run time (the OpenCL C that opencl/source.cpp writes into
// strings), bodies whose braces differ between the branches of an #if, a constructor whose
// initializer list brace-initializes a member (`x_{...}`: the body is then not measured), and
// lambdas or local classes, which count toward the function around them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

constexpr int kMaxFunctionLines = 80;

// `text` with comments, literals and preprocessor lines replaced by spaces (a literal by its two
// quotes); every newline stays, so line numbers are those of the file.
std::string code_only(const std::string& text) {
  std::string out;
  const std::size_t n = text.size();
  auto skip_to = [&](std::size_t from, std::size_t to) {  // blanks text[from, to), keeps newlines
    for (std::size_t k = from; k < to && k < n; ++k) out += text[k] == '\n' ? '\n' : ' ';
  };
  auto starts_line = [&](std::size_t k) {  // nothing but blanks before text[k] on its line
    while (k > 0 && (text[k - 1] == ' ' || text[k - 1] == '\t')) --k;
    return k == 0 || text[k - 1] == '\n';
  };
  std::size_t i = 0;
  while (i < n) {
    const bool after_identifier =
        i > 0 && (std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '_');
    if (text.compare(i, 2, "//") == 0) {
      const std::size_t end = text.find('\n', i);
      skip_to(i, end == std::string::npos ? n : end);
      i = end == std::string::npos ? n : end;
    } else if (text.compare(i, 2, "/*") == 0) {
      const std::size_t close = text.find("*/", i + 2);
      const std::size_t end = close == std::string::npos ? n : close + 2;
      skip_to(i, end);
      i = end;
    } else if (text[i] == 'R' && !after_identifier && i + 1 < n && text[i + 1] == '"') {
      const std::size_t open = text.find('(', i);
      const std::string close = ")" + text.substr(i + 2, open - i - 2) + "\"";
      const std::size_t at = open == std::string::npos ? std::string::npos : text.find(close, open);
      const std::size_t end = at == std::string::npos ? n : at + close.size();
      out += "\"\"";
      skip_to(i + 2, end);
      i = end;
    } else if (text[i] == '"' || (text[i] == '\'' && !after_identifier)) {  // not a digit separator
      std::size_t end = i + 1;
      while (end < n && text[end] != text[i] && text[end] != '\n') end += text[end] == '\\' ? 2 : 1;
      out += text[i];
      out += text[i];
      i = end + 1;
    } else if (text[i] == '#' && starts_line(i)) {
      std::size_t end = i;
      do end = text.find('\n', end + 1);
      while (end != std::string::npos && text[end - 1] == '\\');
      end = end == std::string::npos ? n : end;
      skip_to(i, end);
      i = end;
    } else {
      out += text[i++];
    }
  }
  return out;
}

struct FunctionSpan {
  int first_line, last_line;  // 1-based, the declaration's first line and the closing brace's
  int lines() const { return last_line - first_line + 1; }
};

// What a declaration's head may start with before its first line: blanks and an access specifier.
const std::regex kLeadingBlanksAndAccess(R"(^\s*((public|protected|private)\s*:\s*)?)");

enum class Block { Scope, Function, Other };  // Scope: a namespace, class or extern "C" block

// What a `{` preceded by `head` (the text since the last `;`, `{` or `}`) opens, given whether it
// is at namespace or class scope.
Block block_of(std::string head, bool at_scope) {
  static const std::regex blanks(R"(\s+)");
  head = std::regex_replace(std::regex_replace(head, kLeadingBlanksAndAccess, ""), blanks, " ");
  static const std::regex scope(R"(^((template ?<.*> ?)?(namespace|class|struct|union|enum)\b|extern\b))");
  static const std::regex control(R"(\b(if|for|while|switch|catch) ?\()");
  if (std::regex_search(head, scope)) return Block::Scope;
  const std::size_t paren = head.find('(');
  if (!at_scope || paren == std::string::npos || std::regex_search(head, control)) return Block::Other;
  const std::string before = head.substr(0, paren);
  // An initializer (`x = f(...) {`) is no definition; `operator==(...)` is.
  if (before.find('=') != std::string::npos && before.find("operator") == std::string::npos) return Block::Other;
  return Block::Function;
}

// Every function body at namespace or class scope of `code` (code_only()'s output).
std::vector<FunctionSpan> function_spans(const std::string& code) {
  std::vector<FunctionSpan> spans;
  std::vector<std::pair<Block, int>> open;  // the blocks around, each with its first line
  std::size_t head_begin = 0;
  int line = 1;
  for (std::size_t i = 0; i < code.size(); ++i) {
    const char c = code[i];
    if (c == '\n') ++line;
    if (c != ';' && c != '{' && c != '}') continue;
    if (c == '{') {
      const std::string head = code.substr(head_begin, i - head_begin);
      bool at_scope = true;
      for (const auto& [block, first] : open) at_scope = at_scope && block == Block::Scope;
      // The head's first line: the lines of the head after its leading blank text.
      const std::string body = std::regex_replace(head, kLeadingBlanksAndAccess, "");
      const int first = line - int(std::count(body.begin(), body.end(), '\n'));
      open.emplace_back(block_of(head, at_scope), first);
    } else if (c == '}' && !open.empty()) {
      if (open.back().first == Block::Function) spans.push_back({open.back().second, line});
      open.pop_back();
    }
    head_begin = i + 1;
  }
  return spans;
}

std::string read(const fs::path& file) {
  std::ifstream input(file);
  std::stringstream text;
  text << input.rdbuf();
  return text.str();
}

TEST(CodeShape, ScannerFindsDefinitionsAndSkipsWhatIsNoCode) {
  const std::string text =
      "namespace a {\n"                         // 1
      "int f(int x,\n"                          // 2
      "      int y) {\n"                        // 3
      "  if (x) { return 1; }\n"                // 4
      "  const char* s = \"}{\"; // }\n"        // 5
      "  return [&] { return y; }();\n"         // 6
      "}\n"                                     // 7
      "class C {\n"                             // 8
      " public:\n"                              // 9
      "  C() : v_(0) {}\n"                      // 10
      "  bool operator==(const C&) const {\n"   // 11
      "#if X\n"                                 // 12
      "    return true; /* { */\n"              // 13
      "#endif\n"                                // 14
      "  }\n"                                   // 15
      "  int v_;\n"                             // 16
      "};\n"                                    // 17
      "const int table[] = {1, 2};\n"           // 18
      "}  // namespace a\n";                    // 19
  const auto spans = function_spans(code_only(text));
  ASSERT_EQ(spans.size(), 3u);
  EXPECT_EQ(spans[0].first_line, 2);
  EXPECT_EQ(spans[0].last_line, 7);
  EXPECT_EQ(spans[1].first_line, 10);
  EXPECT_EQ(spans[1].lines(), 1);
  EXPECT_EQ(spans[2].first_line, 11);
  EXPECT_EQ(spans[2].last_line, 15);
  EXPECT_EQ(code_only("auto r = R\"x(a\n})x\";\n"), "auto r = \"\"   \n    ;\n");
}

TEST(CodeShape, NoFunctionIsLongerThanEightyLines) {
  const fs::path root = AMYTISS_SOURCE_DIR;
  std::size_t functions = 0;
  for (const char* folder : {"src/core", "src/cli", "src/ros", "src/nodes"}) {
    for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
      const std::string extension = entry.path().extension().string();
      if (!entry.is_regular_file() ||
          (extension != ".cpp" && extension != ".hpp" && extension != ".h" && extension != ".cl"))
        continue;
      for (const FunctionSpan& span : function_spans(code_only(read(entry.path())))) {
        ++functions;
        EXPECT_LE(span.lines(), kMaxFunctionLines)
            << fs::relative(entry.path(), root).generic_string() << ":" << span.first_line << ": a function of "
            << span.lines() << " lines";
      }
    }
  }
  // Guards against a wrong root or a broken scan making the check vacuous.
  EXPECT_GE(functions, 1000u);
}

}  // namespace
