#include "common/process/arg_parser.h"

#include <cmath>
#include <iostream>
#include <sstream>

namespace vimot {

std::vector<std::string> split_comma_list(const std::string& list) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = list.find(',', start);
    const std::string item = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (!item.empty()) out.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

int run_main(const char* program, int argc, char** argv, int (*run)(int, const char* const*)) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    // ArgParser's own errors already name the program.
    const std::string prefix = std::string(program) + ": ";
    const std::string what = e.what();
    std::cerr << (what.compare(0, prefix.size(), prefix) == 0 ? "" : prefix) << what << "\n";
    return 1;
  }
}

ArgParser::ArgParser(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {
  add_flag("help", "print this help and exit");
}

void ArgParser::add_option(const std::string& name, const std::string& value_name, const std::string& help,
                           const std::string& fallback) {
  if (specs_.count(name)) throw std::logic_error("ArgParser: option --" + name + " declared twice");
  specs_[name] = Spec{value_name.empty() ? "VALUE" : value_name, help, fallback};
  order_.push_back(name);
}

void ArgParser::add_flag(const std::string& name, const std::string& help) {
  if (specs_.count(name)) throw std::logic_error("ArgParser: flag --" + name + " declared twice");
  specs_[name] = Spec{"", help, ""};
  order_.push_back(name);
}

void ArgParser::set_positional(const std::string& usage, const std::string& help, int min_count, int max_count) {
  positional_usage_ = usage;
  positional_help_ = help;
  min_positionals_ = min_count;
  max_positionals_ = max_count;
}

const ArgParser::Spec& ArgParser::spec(const std::string& name) const {
  const auto it = specs_.find(name);
  if (it == specs_.end()) throw std::logic_error("ArgParser: option --" + name + " was never declared");
  return it->second;
}

bool ArgParser::parse(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << usage();
      return false;
    }
    if (arg.rfind("--", 0) != 0 || arg.size() == 2) {
      positionals_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2);
    std::string value;
    bool has_inline_value = false;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_inline_value = true;
    }
    const auto it = specs_.find(name);
    if (it == specs_.end()) throw ArgError(program_ + ": unknown option '" + arg + "' (see --help)");
    if (it->second.value_name.empty()) {
      if (has_inline_value) throw ArgError(program_ + ": flag --" + name + " takes no value");
      values_[name] = "1";
      continue;
    }
    if (!has_inline_value) {
      if (i + 1 >= argc) throw ArgError(program_ + ": option --" + name + " needs a " + it->second.value_name);
      value = argv[++i];
    }
    values_[name] = value;
  }
  const int n = static_cast<int>(positionals_.size());
  if (n < min_positionals_ || n > max_positionals_) {
    std::ostringstream msg;
    msg << program_ << ": expected ";
    if (min_positionals_ == max_positionals_) msg << min_positionals_;
    else msg << min_positionals_ << " to " << max_positionals_;
    msg << " positional argument(s) " << positional_usage_ << ", got " << n << " (see --help)";
    throw ArgError(msg.str());
  }
  return true;
}

std::string ArgParser::get(const std::string& name) const {
  const Spec& s = spec(name);
  const auto it = values_.find(name);
  return it == values_.end() ? s.fallback : it->second;
}

bool ArgParser::given(const std::string& name) const {
  spec(name);
  return values_.count(name) > 0;
}

bool ArgParser::flag(const std::string& name) const { return given(name); }

double ArgParser::get_double(const std::string& name) const {
  const std::string text = get(name);
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || !std::isfinite(v)) {
    throw ArgError(program_ + ": option --" + name + " must be a finite number, got '" + text + "'");
  }
  return v;
}

long long ArgParser::get_int(const std::string& name) const {
  const std::string text = get(name);
  std::size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty()) {
    throw ArgError(program_ + ": option --" + name + " must be an integer, got '" + text + "'");
  }
  return v;
}

std::string ArgParser::usage() const {
  std::ostringstream out;
  out << "usage: " << program_ << " [options]";
  if (!positional_usage_.empty()) out << " " << positional_usage_;
  out << "\n\n" << summary_ << "\n\n";
  if (!positional_help_.empty()) out << "  " << positional_usage_ << "\n      " << positional_help_ << "\n";
  out << "options:\n";
  for (const std::string& name : order_) {
    const Spec& s = specs_.at(name);
    std::string head = "  --" + name + (s.value_name.empty() ? "" : " " + s.value_name);
    out << head << "\n      " << s.help;
    if (!s.fallback.empty()) out << " (default: " << s.fallback << ")";
    out << "\n";
  }
  return out.str();
}

}  // namespace vimot
