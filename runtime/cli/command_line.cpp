#include "runtime/cli/command_line.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <sstream>

namespace sinew::cli {

// The usage line first, as Unix tools print it, then the description, the
// options and the footer (CLI11 puts the description first).
class UsageFirstFormatter : public CLI::Formatter {
 public:
  UsageFirstFormatter() {
    label("Usage", "usage");
    label("SUBCOMMAND", "COMMAND");
    label("Subcommands", "Commands");
    column_width(34);
  }
  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
    if (mode == CLI::AppFormatMode::Sub) return make_expanded(app);
    std::ostringstream out;
    out << make_usage(app, name);
    std::string description = make_description(app);
    while (!description.empty() && description.back() == '\n') description.pop_back();
    if (!description.empty()) out << "\n" << description << "\n";
    out << make_positionals(app) << make_groups(app, mode) << make_subcommands(app, mode);
    const std::string footer = make_footer(app);
    if (!footer.empty()) out << "\n" << footer;
    return out.str();
  }
  // Positionals are collected as a list (parse() checks the count, naming
  // the first one too many): show "[MODEL]" or "[FILE...]" by the real limit.
  std::string make_option_usage(const CLI::Option* opt) const override {
    return "[" + make_option_name(opt, true) + (positional_max > 1 ? "..." : "") + "]";
  }
  std::string make_option_opts(const CLI::Option* opt) const override {
    return opt->get_positional() ? std::string() : CLI::Formatter::make_option_opts(opt);
  }

  std::size_t positional_max = 0;
};

namespace {

bool looks_like_option(const std::string& arg) { return arg.size() > 1 && arg[0] == '-'; }

// CLI11's own errors, in Sinew's "FLAG = VALUE: what is wrong" form. Its
// messages start with the option's name ("--size: 1 required WxH missing").
Status from_cli11(const CLI::ParseError& e) {
  const std::string what = e.what();
  const std::size_t colon = what.find(": ");
  const std::string name = colon == std::string::npos ? std::string("option") : what.substr(0, colon);
  const std::string detail = colon == std::string::npos ? what : what.substr(colon + 2);
  if (e.get_name() == "ArgumentMismatch") {
    if (detail.find("At Most") != std::string::npos) return invalid_argument(name, "", "given more than once");
    if (detail.find("missing") != std::string::npos) return invalid_argument(name, "", "missing value");
  }
  return invalid_argument(name, "", detail);
}

}  // namespace

CommandLine::CommandLine(std::string program, std::string description)
    : program_(std::move(program)), app_(std::make_unique<CLI::App>(std::move(description), program_)) {
  formatter_ = std::make_shared<UsageFirstFormatter>();
  app_->formatter(formatter_);
  app_->set_help_flag("-h,--help", "print this help and exit");
  // Unknown arguments are collected and reported here, by name.
  app_->allow_extras();
}

CommandLine::~CommandLine() = default;

const std::optional<std::string>& CommandLine::option(const std::string& names, const std::string& value_form,
                                                      const std::string& help) {
  std::optional<std::string>& text = texts_.emplace_back();
  app_->add_option(names, text, help)->type_name(value_form);
  return text;
}

const std::vector<std::string>& CommandLine::repeated_option(const std::string& names, const std::string& value_form,
                                                             const std::string& help) {
  std::vector<std::string>& texts = lists_.emplace_back();
  // One value per occurrence, every occurrence kept.
  app_->add_option(names, texts, help)
      ->type_name(value_form + " (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  return texts;
}

const bool& CommandLine::flag(const std::string& names, const std::string& help) {
  bool& given = switches_.emplace_back(false);
  app_->add_flag(names, given, help);
  return given;
}

const std::vector<std::string>& CommandLine::positionals(const std::string& name, const std::string& help,
                                                         std::size_t max) {
  max_positionals_ = max;
  formatter_->positional_max = max;
  // Any number is collected: parse() reports the first one too many by name.
  app_->add_option(name, positionals_, help)->type_name("");
  return positionals_;
}

void CommandLine::command(const std::string& name, const std::string& help) {
  CLI::App* sub = app_->add_subcommand(name, help);
  // The command parses its own arguments, --help included. One command per
  // line: without the bound, an argument of the first that names another
  // command ("report --sections tradeoff") would start that one instead.
  app_->require_subcommand(0, 1);
  sub->prefix_command();
  sub->set_help_flag();
  commands_.push_back(name);
}

void CommandLine::footer(const std::string& text) { app_->footer(text); }

Expected<ParseResult> CommandLine::parse(const std::vector<std::string>& args) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app_->parse(reversed);
  } catch (const CLI::CallForHelp&) {
    return ParseResult::kHelp;
  } catch (const CLI::ParseError& e) {
    return from_cli11(e);
  }
  for (const CLI::App* sub : app_->get_subcommands()) {
    chosen_command_ = sub->get_name();
    command_arguments_ = sub->remaining();
  }
  std::vector<std::string> extras = app_->remaining();
  extras.erase(std::remove(extras.begin(), extras.end(), "--"), extras.end());
  for (const std::string& extra : extras) {
    if (looks_like_option(extra)) return invalid_argument("option", extra, "unknown option (see --help)");
  }
  if (!extras.empty()) {
    if (!commands_.empty()) return invalid_argument("command", extras.front(), "unknown command (see --help)");
    return invalid_argument("argument", extras.front(), "unexpected argument (see --help)");
  }
  if (positionals_.size() > max_positionals_) {
    return invalid_argument("argument", positionals_[max_positionals_],
                            "unexpected argument (at most " + std::to_string(max_positionals_) + ")");
  }
  return ParseResult::kRun;
}

std::string CommandLine::help() const { return app_->help(); }

std::optional<int> help_or_usage_error(const CommandLine& line, const Expected<ParseResult>& parsed,
                                       std::ostream& out, std::ostream& err) {
  if (!parsed.ok()) return usage_error(line.program(), parsed.status(), err);
  if (*parsed == ParseResult::kHelp) {
    out << line.help();
    return 0;
  }
  return std::nullopt;
}

int usage_error(const std::string& program, const Status& status, std::ostream& err) {
  err << program << ": " << status.message() << "\n";
  return 2;
}

}  // namespace sinew::cli
