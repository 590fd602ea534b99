#include "procs/sheriff/sheriff_config_parser.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

namespace vimot::sheriff {

namespace {

enum class TokenType {
  kIdentifier,
  kString,
  kInteger,
  kOpenBrace,
  kCloseBrace,
  kAssign,
  kSemicolon,
  kEnd,
};

struct Token {
  TokenType type{TokenType::kEnd};
  std::string text;  // Unescaped contents for strings.
  int line{0};
  int column{0};
};

std::string Describe(const Token& token) {
  switch (token.type) {
    case TokenType::kIdentifier:
      return "identifier '" + token.text + "'";
    case TokenType::kString:
      return "string \"" + token.text + "\"";
    case TokenType::kInteger:
      return "integer " + token.text;
    case TokenType::kOpenBrace:
      return "'{'";
    case TokenType::kCloseBrace:
      return "'}'";
    case TokenType::kAssign:
      return "'='";
    case TokenType::kSemicolon:
      return "';'";
    case TokenType::kEnd:
      break;
  }
  return "end of file";
}

// Splits the text into tokens up front; configs are small and a token vector
// makes one-token lookahead trivial.
class Tokenizer {
 public:
  Tokenizer(std::string_view text, const std::string& file_name)
      : text_(text), file_name_(file_name) {}

  std::vector<Token> Run() {
    std::vector<Token> tokens;
    while (true) {
      SkipSpaceAndComments();
      Token token;
      token.line = line_;
      token.column = column_;
      if (pos_ == text_.size()) {
        tokens.push_back(token);
        return tokens;
      }
      const char c = text_[pos_];
      if (c == '{' || c == '}' || c == '=' || c == ';') {
        token.type = c == '{'   ? TokenType::kOpenBrace
                     : c == '}' ? TokenType::kCloseBrace
                     : c == '=' ? TokenType::kAssign
                                : TokenType::kSemicolon;
        token.text = std::string(1, c);
        Advance();
      } else if (c == '"') {
        token.type = TokenType::kString;
        token.text = ReadString(token);
      } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
        token.type = TokenType::kIdentifier;
        while (pos_ < text_.size() &&
               (std::isalnum(static_cast<unsigned char>(text_[pos_])) ||
                text_[pos_] == '_' || text_[pos_] == '-')) {
          token.text.push_back(text_[pos_]);
          Advance();
        }
      } else if (std::isdigit(static_cast<unsigned char>(c)) ||
                 (c == '-' && pos_ + 1 < text_.size() &&
                  std::isdigit(static_cast<unsigned char>(text_[pos_ + 1])))) {
        token.type = TokenType::kInteger;
        do {
          token.text.push_back(text_[pos_]);
          Advance();
        } while (pos_ < text_.size() &&
                 std::isdigit(static_cast<unsigned char>(text_[pos_])));
      } else {
        const std::string shown =
            std::isprint(static_cast<unsigned char>(c))
                ? std::string("'") + c + "'"
                : "byte " + std::to_string(static_cast<unsigned char>(c));
        Fail(token, "unexpected character " + shown +
                        " (expected 'cmd', 'group', 'script', a string, an "
                        "integer, '{', '}', '=', ';' or a '#' comment)");
      }
      tokens.push_back(std::move(token));
    }
  }

  [[noreturn]] void Fail(const Token& at, const std::string& message) const {
    throw ConfigParseError({file_name_, at.line, at.column}, message,
                           SourceLine(at.line));
  }

  std::string SourceLine(int line) const {
    std::size_t start = 0;
    for (int l = 1; l < line && start != std::string_view::npos; ++l) {
      start = text_.find('\n', start);
      if (start != std::string_view::npos) ++start;
    }
    if (start == std::string_view::npos || start > text_.size()) return "";
    const std::size_t end = text_.find('\n', start);
    return std::string(text_.substr(
        start, end == std::string_view::npos ? std::string_view::npos
                                             : end - start));
  }

 private:
  void Advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      column_ = 1;
    } else {
      ++column_;
    }
    ++pos_;
  }

  void SkipSpaceAndComments() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '#') {
        while (pos_ < text_.size() && text_[pos_] != '\n') Advance();
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        Advance();
      } else {
        return;
      }
    }
  }

  std::string ReadString(const Token& start) {
    std::string value;
    Advance();  // Opening quote.
    while (true) {
      if (pos_ == text_.size() || text_[pos_] == '\n') {
        Fail(start, "unterminated string (expected a closing '\"' before the "
                    "end of the line)");
      }
      const char c = text_[pos_];
      Advance();
      if (c == '"') return value;
      if (c != '\\') {
        value.push_back(c);
        continue;
      }
      if (pos_ == text_.size() || text_[pos_] == '\n') {
        Fail(start, "unterminated string (a '\\' ends the line)");
      }
      const char escaped = text_[pos_];
      Advance();
      switch (escaped) {
        case 'n':
          value.push_back('\n');
          break;
        case 't':
          value.push_back('\t');
          break;
        case 'r':
          value.push_back('\r');
          break;
        default:  // \" \\ and, as in procman, any other character itself.
          value.push_back(escaped);
          break;
      }
    }
  }

  std::string_view text_;
  const std::string& file_name_;
  std::size_t pos_{0};
  int line_{1};
  int column_{1};
};

// Recursive-descent parser over the token vector.
class Parser {
 public:
  Parser(std::string_view text, const std::string& file_name)
      : tokenizer_(text, file_name), file_name_(file_name) {
    tokens_ = tokenizer_.Run();
  }

  SheriffConfig Parse() {
    while (Peek().type != TokenType::kEnd) {
      const Token& keyword = Next();
      if (keyword.type == TokenType::kIdentifier && keyword.text == "cmd") {
        ParseCommand("");
      } else if (keyword.type == TokenType::kIdentifier &&
                 keyword.text == "group") {
        ParseGroup("");
      } else if (keyword.type == TokenType::kIdentifier &&
                 keyword.text == "script") {
        ParseScript();
      } else {
        Fail(keyword, "expected 'cmd', 'group' or 'script', found " +
                          Describe(keyword));
      }
    }
    CheckScriptReferences();
    return std::move(config_);
  }

 private:
  const Token& Peek() const { return tokens_[index_]; }

  const Token& Next() {
    const Token& token = tokens_[index_];
    if (token.type != TokenType::kEnd) ++index_;
    return token;
  }

  SourceLocation Location(const Token& token) const {
    return {file_name_, token.line, token.column};
  }

  [[noreturn]] void Fail(const Token& at, const std::string& message) const {
    tokenizer_.Fail(at, message);
  }

  [[noreturn]] void Fail(const SourceLocation& at,
                         const std::string& message) const {
    throw ConfigParseError(at, message, tokenizer_.SourceLine(at.line));
  }

  // Consumes a token of `type`, or fails with "expected <what>, found ...".
  const Token& Expect(TokenType type, const std::string& what) {
    const Token& token = Next();
    if (token.type != type) {
      Fail(token, "expected " + what + ", found " + Describe(token));
    }
    return token;
  }

  // Consumes the identifier `word`, or fails.
  void ExpectKeyword(const std::string& word, const std::string& context) {
    const Token& token = Next();
    if (token.type != TokenType::kIdentifier || token.text != word) {
      Fail(token, "expected '" + word + "' " + context + ", found " +
                      Describe(token));
    }
  }

  // Consumes one of the identifiers `words`, or fails listing them.
  const Token& ExpectOneOf(const std::vector<std::string>& words,
                           const std::string& context) {
    const Token& token = Next();
    if (token.type == TokenType::kIdentifier) {
      for (const std::string& w : words) {
        if (token.text == w) return token;
      }
    }
    std::string list;
    for (std::size_t i = 0; i < words.size(); ++i) {
      list += (i == 0 ? "'" : i + 1 == words.size() ? " or '" : ", '") +
              words[i] + "'";
    }
    Fail(token, "expected " + list + " " + context + ", found " +
                    Describe(token));
  }

  WaitStatus ExpectWaitStatus() {
    const Token& token = Next();
    if (token.type == TokenType::kString && token.text == "running") {
      return WaitStatus::kRunning;
    }
    if (token.type == TokenType::kString && token.text == "stopped") {
      return WaitStatus::kStopped;
    }
    Fail(token, "expected \"running\" or \"stopped\", found " +
                    Describe(token));
  }

  void ParseGroup(const std::string& parent) {
    const Token& name = Expect(TokenType::kString, "a group name string");
    if (name.text.find('/') != std::string::npos) {
      Fail(name, "'/' is not allowed in a group name (it separates nested "
                 "groups); found \"" + name.text + "\"");
    }
    bool blank = true;
    for (const char c : name.text) {
      blank = blank && std::isspace(static_cast<unsigned char>(c));
    }
    if (blank) Fail(name, "expected a non-empty group name");
    const std::string full = parent.empty() ? name.text : parent + "/" + name.text;
    // Checked before descending: each level is a recursive call.
    if (SheriffConfig::GroupDepth(SheriffConfig::NormalizeGroupName(full)) > kMaxGroupDepth) {
      Fail(name, "groups nest more than " + std::to_string(kMaxGroupDepth) +
                     " levels deep (group \"" + name.text + "\")");
    }
    config_.AddGroup(full, Location(name));
    Expect(TokenType::kOpenBrace, "'{' after group \"" + name.text + "\"");
    while (true) {
      const Token& token = Next();
      if (token.type == TokenType::kCloseBrace) return;
      if (token.type == TokenType::kIdentifier && token.text == "cmd") {
        ParseCommand(full);
      } else if (token.type == TokenType::kIdentifier && token.text == "group") {
        ParseGroup(full);
      } else {
        Fail(token, "expected 'cmd', 'group' or '}' in group \"" + full +
                        "\", found " + Describe(token));
      }
    }
  }

  // Integer attribute value, given bare or as a string (some configs quote
  // everything).
  long ParseIntegerValue(const Token& value, const std::string& attribute) {
    if (value.type == TokenType::kInteger || value.type == TokenType::kString) {
      const std::string& t = value.text;
      std::size_t digits_from = (!t.empty() && t[0] == '-') ? 1 : 0;
      bool ok = t.size() > digits_from && t.size() < 12;
      for (std::size_t i = digits_from; i < t.size(); ++i) {
        ok = ok && std::isdigit(static_cast<unsigned char>(t[i]));
      }
      if (ok) return std::stol(t);
    }
    Fail(value, "expected an integer for '" + attribute + "', found " +
                    Describe(value));
  }

  void ParseCommand(const std::string& enclosing_group) {
    const Token& name = Expect(TokenType::kString, "a command name string");
    if (name.text.empty()) Fail(name, "expected a non-empty command name");
    if (name.text.find('/') != std::string::npos) {
      Fail(name, "'/' is not allowed in a command name; found \"" +
                     name.text + "\"");
    }
    if (const CommandSpec* other = config_.FindCommand(name.text)) {
      Fail(name, "duplicate command name \"" + name.text +
                     "\" (first defined at " + other->location.ToString() +
                     ")");
    }
    CommandSpec cmd;
    cmd.name = name.text;
    cmd.group = enclosing_group;
    cmd.location = Location(name);
    Expect(TokenType::kOpenBrace, "'{' after cmd \"" + name.text + "\"");
    std::set<std::string> seen;
    bool has_exec = false;
    while (true) {
      const Token& key = Next();
      if (key.type == TokenType::kCloseBrace) break;
      if (key.type != TokenType::kIdentifier) {
        Fail(key, "expected an attribute name or '}' in cmd \"" + cmd.name +
                      "\", found " + Describe(key));
      }
      if (!seen.insert(key.text).second) {
        Fail(key, "attribute '" + key.text + "' given twice in cmd \"" +
                      cmd.name + "\"");
      }
      Expect(TokenType::kAssign, "'=' after '" + key.text + "'");
      const Token& value = Next();
      if (value.type != TokenType::kString && value.type != TokenType::kInteger) {
        Fail(value, "expected a string or integer value for '" + key.text +
                        "', found " + Describe(value));
      }
      if (key.text == "exec") {
        if (value.type != TokenType::kString) {
          Fail(value, "expected a string for 'exec', found " + Describe(value));
        }
        cmd.exec = value.text;
        has_exec = true;
      } else if (key.text == "host") {
        cmd.host = value.text;
      } else if (key.text == "auto_respawn") {
        if (value.text == "true") {
          cmd.auto_respawn = true;
        } else if (value.text == "false") {
          cmd.auto_respawn = false;
        } else {
          Fail(value, "expected \"true\" or \"false\" for 'auto_respawn', "
                      "found " + Describe(value));
        }
      } else if (key.text == "stop_signal") {
        const long signal = ParseIntegerValue(value, key.text);
        if (signal < 1 || signal >= NSIG) {
          Fail(value, "'stop_signal' must be a signal number in [1, " +
                          std::to_string(NSIG - 1) + "], got " +
                          std::to_string(signal));
        }
        cmd.stop_signal = static_cast<int>(signal);
      } else if (key.text == "stop_time_allowed") {
        const long seconds = ParseIntegerValue(value, key.text);
        if (seconds < 1 || seconds > 24 * 3600) {
          Fail(value, "'stop_time_allowed' must be a number of seconds in "
                      "[1, 86400], got " + std::to_string(seconds));
        }
        cmd.stop_time_allowed = std::chrono::seconds(seconds);
      } else if (key.text == "group") {
        const std::string group = SheriffConfig::NormalizeGroupName(value.text);
        if (SheriffConfig::GroupDepth(group) > kMaxGroupDepth) {
          Fail(value, "group path of cmd \"" + cmd.name + "\" nests more than " +
                          std::to_string(kMaxGroupDepth) + " levels deep");
        }
        if (!enclosing_group.empty() && group != enclosing_group) {
          Fail(value, "cmd \"" + cmd.name + "\" is inside group \"" +
                          enclosing_group + "\" but says group = \"" +
                          value.text + "\"");
        }
        cmd.group = group;
      } else {
        cmd.extra_attributes.emplace_back(key.text, value.text);
        config_.AddWarning({Location(key), "unknown attribute '" + key.text +
                                               "' in cmd \"" + cmd.name +
                                               "\" (kept, not used)"});
      }
      Expect(TokenType::kSemicolon,
             "';' after the value of '" + key.text + "'");
    }
    if (!has_exec) {
      Fail(name, "cmd \"" + cmd.name + "\" has no 'exec' attribute (expected "
                 "exec = \"...\";)");
    }
    config_.AddCommand(std::move(cmd));
  }

  // After `start|stop|restart` or `wait`: cmd "x" | group "g" | everything.
  void ParseTarget(ScriptAction* action, bool allow_everything) {
    const Token& kind =
        allow_everything
            ? ExpectOneOf({"cmd", "group", "everything"},
                          "after '" + ActionWord(*action) + "'")
            : ExpectOneOf({"ms", "cmd", "group"}, "after 'wait'");
    if (kind.text == "everything") {
      action->target = ActionTarget::kEverything;
      return;
    }
    action->target =
        kind.text == "cmd" ? ActionTarget::kCommand : ActionTarget::kGroup;
    const Token& name =
        Expect(TokenType::kString, "a " + kind.text + " name string");
    action->name = kind.text == "group"
                       ? SheriffConfig::NormalizeGroupName(name.text)
                       : name.text;
  }

  static std::string ActionWord(const ScriptAction& action) {
    switch (action.kind) {
      case ActionKind::kStart:
        return "start";
      case ActionKind::kStop:
        return "stop";
      case ActionKind::kRestart:
        return "restart";
      default:
        break;
    }
    return "wait";
  }

  void ParseScript() {
    const Token& name = Expect(TokenType::kString, "a script name string");
    if (name.text.empty()) Fail(name, "expected a non-empty script name");
    if (const ScriptSpec* other = config_.FindScript(name.text)) {
      Fail(name, "duplicate script name \"" + name.text +
                     "\" (first defined at " + other->location.ToString() +
                     ")");
    }
    ScriptSpec script;
    script.name = name.text;
    script.location = Location(name);
    Expect(TokenType::kOpenBrace, "'{' after script \"" + name.text + "\"");
    while (true) {
      const Token& word = Next();
      if (word.type == TokenType::kCloseBrace) break;
      ScriptAction action;
      action.location = Location(word);
      if (word.type == TokenType::kIdentifier &&
          (word.text == "start" || word.text == "stop" ||
           word.text == "restart")) {
        action.kind = word.text == "start"  ? ActionKind::kStart
                      : word.text == "stop" ? ActionKind::kStop
                                            : ActionKind::kRestart;
        ParseTarget(&action, true);
        const Token& after = Peek();
        if (after.type == TokenType::kIdentifier && after.text == "wait") {
          Next();
          action.wait = ExpectWaitStatus();
        } else if (after.type != TokenType::kSemicolon) {
          Fail(after, "expected ';' or 'wait' after " + word.text +
                          " target, found " + Describe(after));
        }
      } else if (word.type == TokenType::kIdentifier && word.text == "wait") {
        action.kind = ActionKind::kWaitStatus;
        if (Peek().type == TokenType::kIdentifier && Peek().text == "ms") {
          Next();
          action.kind = ActionKind::kWaitMs;
          const Token& ms = Expect(TokenType::kInteger,
                                   "a number of milliseconds after 'wait ms'");
          const long value = ParseIntegerValue(ms, "wait ms");
          if (value < 0) {
            Fail(ms, "'wait ms' needs a non-negative delay, got " + ms.text);
          }
          action.delay = std::chrono::milliseconds(value);
        } else {
          ParseTarget(&action, false);
          ExpectKeyword("status", "after the wait target");
          action.wait = ExpectWaitStatus();
        }
      } else if (word.type == TokenType::kIdentifier &&
                 word.text == "run_script") {
        action.kind = ActionKind::kRunScript;
        action.target = ActionTarget::kScript;
        action.name =
            Expect(TokenType::kString, "a script name string after "
                                       "'run_script'").text;
      } else {
        Fail(word, "expected a script action ('start', 'stop', 'restart', "
                   "'wait', 'run_script') or '}', found " + Describe(word));
      }
      Expect(TokenType::kSemicolon, "';' after the script action");
      script.actions.push_back(std::move(action));
    }
    config_.AddScript(std::move(script));
  }

  // Scripts may refer to things defined later in the file, so references are
  // checked once everything is read.
  void CheckScriptReferences() const {
    for (const ScriptSpec& script : config_.scripts()) {
      for (const ScriptAction& action : script.actions) {
        if (action.target == ActionTarget::kCommand &&
            config_.FindCommand(action.name) == nullptr) {
          Fail(action.location, "script \"" + script.name +
                                    "\" refers to unknown cmd \"" +
                                    action.name + "\"");
        }
        if (action.target == ActionTarget::kGroup &&
            config_.FindGroup(action.name) == nullptr) {
          Fail(action.location, "script \"" + script.name +
                                    "\" refers to unknown group \"" +
                                    action.name + "\"");
        }
        if (action.target == ActionTarget::kScript &&
            config_.FindScript(action.name) == nullptr) {
          Fail(action.location, "script \"" + script.name +
                                    "\" runs unknown script \"" + action.name +
                                    "\"");
        }
      }
    }
    // run_script must not recurse (the sheriff would never finish) nor nest
    // without bound. Depth-first over an explicit stack: a generated chain
    // of 40 000 scripts must not overflow the parser's own stack.
    std::map<std::string, int> height;  // longest run_script chain; -1 on the path
    for (const ScriptSpec& script : config_.scripts()) {
      if (height.count(script.name) == 0) CheckRunScripts(script, &height);
    }
  }

  void CheckRunScripts(const ScriptSpec& root, std::map<std::string, int>* height) const {
    struct Frame {
      const ScriptSpec* script;
      std::size_t next_action;
      int max_child_height;
    };
    std::vector<Frame> path{{&root, 0, 0}};
    (*height)[root.name] = -1;
    while (!path.empty()) {
      Frame& top = path.back();
      if (top.next_action == top.script->actions.size()) {
        const int h = top.max_child_height + 1;
        if (h > kMaxScriptNesting) {
          Fail(top.script->location, "run_script nests scripts more than " +
                                         std::to_string(kMaxScriptNesting) + " deep, starting at script \"" +
                                         top.script->name + "\"");
        }
        (*height)[top.script->name] = h;
        path.pop_back();
        if (!path.empty()) path.back().max_child_height = std::max(path.back().max_child_height, h);
        continue;
      }
      const ScriptAction& action = top.script->actions[top.next_action++];
      if (action.kind != ActionKind::kRunScript) continue;
      const auto known = height->find(action.name);
      if (known != height->end() && known->second > 0) {
        top.max_child_height = std::max(top.max_child_height, known->second);
        continue;
      }
      if (known != height->end()) {
        std::string cycle;
        bool in_cycle = false;
        for (const Frame& f : path) {
          in_cycle = in_cycle || f.script->name == action.name;
          if (in_cycle) cycle += "\"" + f.script->name + "\" -> ";
        }
        Fail(action.location,
             "run_script makes scripts call each other forever: " + cycle +
                 "\"" + action.name + "\"");
      }
      (*height)[action.name] = -1;
      path.push_back({config_.FindScript(action.name), 0, 0});
    }
  }

  Tokenizer tokenizer_;
  const std::string& file_name_;
  std::vector<Token> tokens_;
  std::size_t index_{0};
  SheriffConfig config_;
};

}  // namespace

ConfigParseError::ConfigParseError(SourceLocation location,
                                   const std::string& message,
                                   const std::string& source_line)
    : std::runtime_error([&]() {
        std::string text = location.ToString() + ": error: " + message;
        if (!source_line.empty()) {
          // Keep tabs in the caret line so the caret lines up in a terminal.
          std::string caret;
          for (int i = 1; i < location.column &&
                          i <= static_cast<int>(source_line.size());
               ++i) {
            caret.push_back(source_line[i - 1] == '\t' ? '\t' : ' ');
          }
          text += "\n  " + source_line + "\n  " + caret + "^";
        }
        return text;
      }()),
      location_(std::move(location)),
      message_(message) {}

SheriffConfig ParseSheriffConfig(std::string_view text,
                                 const std::string& file_name) {
  return Parser(text, file_name).Parse();
}

SheriffConfig LoadSheriffConfig(const std::string& path) {
  // An ifstream opens a directory without complaint and reads nothing: the
  // config would silently be empty.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw std::runtime_error("sheriff config '" + path + "' is a directory, not a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw std::runtime_error("cannot open sheriff config '" + path +
                             "': " + std::strerror(errno));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    throw std::runtime_error("cannot read sheriff config '" + path + "'");
  }
  return ParseSheriffConfig(text.str(), path);
}

}  // namespace vimot::sheriff
