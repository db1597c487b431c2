#pragma once
/// Command-line parsing for `balloon` subcommands: `--name value`, `--name=value`, boolean flags and
/// positionals, with errors that name the offending argument.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "result.hpp"

namespace balloon::cli {

/// One accepted option of a subcommand.
struct OptionSpec {
  std::string name;         ///< without dashes, e.g. "pressure"
  bool takes_value = true;  ///< false for boolean flags such as --json
  bool repeatable = false;  ///< may be given more than once
};

/// The parsed command line of one subcommand.
struct ParsedArgs {
  std::vector<std::string> positionals;
  std::map<std::string, std::vector<std::string>> options;  ///< by name, values in order given

  bool has(const std::string& name) const { return options.count(name) != 0; }
  /// The (last) value of an option, if given.
  std::optional<std::string> get(const std::string& name) const;
};

/// Parses `args` (the words after the subcommand). Unknown options, missing values and repeated
/// non-repeatable options are errors. `--` ends the options.
Result<ParsedArgs> parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs);

/// Takes the options named in `specs` out of `args` wherever they stand (up to a `--`), and leaves every
/// other word in `rest`, in order: how the global and job options are found before or after the
/// command's own. Same errors as parse_args for the options it knows; a word after an unknown option is
/// left as it is (the command's own parser decides whether it is that option's value).
Result<ParsedArgs> take_options(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                                std::vector<std::string>* rest);

/// A finite number, or an error naming the option: "--pressure: 'abc' is not a number".
Result<double> parse_number(const std::string& option, const std::string& text);
/// An integer in [min_value, max_value], or an error naming the option.
Result<long long> parse_integer(const std::string& option, const std::string& text, long long min_value,
                                long long max_value);

}  // namespace balloon::cli
