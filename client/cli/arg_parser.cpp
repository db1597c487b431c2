#include "arg_parser.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace balloon::cli {

std::optional<std::string> ParsedArgs::get(const std::string& name) const {
  const auto it = options.find(name);
  if (it == options.end() || it->second.empty()) return std::nullopt;
  return it->second.back();
}

namespace {

/// parse_args and take_options in one: with `rest`, unknown options and positionals go there instead.
Result<ParsedArgs> parse_known(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                               std::vector<std::string>* rest) {
  ParsedArgs parsed;
  bool options_ended = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (rest != nullptr && (options_ended || word == "--")) {
      rest->push_back(word);  // `--` and what follows belong to the command
      options_ended = true;
      continue;
    }
    if (options_ended || word.size() < 2 || word.rfind("--", 0) != 0) {
      if (rest != nullptr) {
        rest->push_back(word);
        continue;
      }
      if (!options_ended && word.size() >= 2 && word[0] == '-' && !(std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.'))
        return fail("unknown option '" + word + "' (options start with --)");
      parsed.positionals.push_back(word);
      continue;
    }
    if (word == "--") {
      options_ended = true;
      continue;
    }
    std::string name = word.substr(2);
    std::optional<std::string> inline_value;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    const OptionSpec* spec = nullptr;
    for (const OptionSpec& candidate : specs)
      if (candidate.name == name) spec = &candidate;
    if (spec == nullptr) {
      if (rest == nullptr) return fail("unknown option '--" + name + "'");
      rest->push_back(word);
      continue;
    }
    if (!spec->repeatable && parsed.has(name)) return fail("option '--" + name + "' given more than once");
    std::string value;
    if (spec->takes_value) {
      if (inline_value) {
        value = *inline_value;
      } else {
        if (i + 1 >= args.size()) return fail("option '--" + name + "' needs a value");
        value = args[++i];
      }
    } else if (inline_value) {
      return fail("option '--" + name + "' takes no value");
    }
    parsed.options[name].push_back(value);
  }
  return parsed;
}

}  // namespace

Result<ParsedArgs> parse_args(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs) {
  return parse_known(args, specs, nullptr);
}

Result<ParsedArgs> take_options(const std::vector<std::string>& args, const std::vector<OptionSpec>& specs,
                                std::vector<std::string>* rest) {
  return parse_known(args, specs, rest);
}

Result<double> parse_number(const std::string& option, const std::string& text) {
  if (text.empty()) return fail("--" + option + ": empty value, expected a number");
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') return fail("--" + option + ": '" + text + "' is not a number");
  if (!std::isfinite(value) || errno == ERANGE) return fail("--" + option + ": '" + text + "' is not a finite number");
  return value;
}

Result<long long> parse_integer(const std::string& option, const std::string& text, long long min_value,
                                long long max_value) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end == text.c_str() || *end != '\0' || errno == ERANGE)
    return fail("--" + option + ": '" + text + "' is not an integer");
  if (value < min_value || value > max_value)
    return fail("--" + option + ": " + text + " is out of range [" + std::to_string(min_value) + ", " +
                std::to_string(max_value) + "]");
  return value;
}

}  // namespace balloon::cli
