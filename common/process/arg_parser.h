#pragma once
// Command-line parsing shared by every vimot executable: `--name value`,
// `--name=value`, flags, positionals, and a generated --help.

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace vimot {

class ArgError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The non-empty items of a comma-separated option value ("a,b,,c" -> a b c).
std::vector<std::string> split_comma_list(const std::string& list);

/// The body of a tool's main(): returns run(argc, argv); an exception that
/// escapes it is reported as "<program>: <what>" on stderr with status 1.
int run_main(const char* program, int argc, char** argv, int (*run)(int, const char* const*));

class ArgParser {
 public:
  ArgParser(std::string program, std::string summary);

  /// An option taking a value; `fallback` is used when it is not given.
  void add_option(const std::string& name, const std::string& value_name, const std::string& help,
                  const std::string& fallback = "");
  /// A boolean flag, false unless given.
  void add_flag(const std::string& name, const std::string& help);
  /// Describes the positional arguments in --help ("LOG_FILE").
  void set_positional(const std::string& usage, const std::string& help, int min_count, int max_count);

  /// Parses argv. Returns false if --help was given (usage already printed to
  /// stdout); throws ArgError with the offending argument otherwise.
  bool parse(int argc, const char* const* argv);

  std::string get(const std::string& name) const;
  bool given(const std::string& name) const;
  bool flag(const std::string& name) const;
  /// Typed getters that name the option in their error.
  double get_double(const std::string& name) const;
  long long get_int(const std::string& name) const;
  const std::vector<std::string>& positionals() const { return positionals_; }

  std::string usage() const;

 private:
  struct Spec {
    std::string value_name;  // empty for a flag
    std::string help;
    std::string fallback;
  };
  const Spec& spec(const std::string& name) const;

  std::string program_;
  std::string summary_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positionals_;
  std::string positional_usage_;
  std::string positional_help_;
  int min_positionals_{0};
  int max_positionals_{0};
};

}  // namespace vimot
