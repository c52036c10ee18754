// What every benchmark run shares around its own measurements: the header
// it prints (what ran, where, when), the identity fields at the top of its
// JSON document, the loop over the models it was asked for, how an error
// is reported (one line, exit code 1, the run goes on), and how --json and
// --markdown are written. Each benchmark adds its own tables and fields.
#pragma once

#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tests/bench/bench_support.h"

namespace sinew::bench {

using Json = nlohmann::ordered_json;

class BenchRecord {
 public:
  // Prints the header (print_bench_header) and starts the document with
  // command, commit, cpu, hardware_threads, isa, date, load_average_start,
  // threads and an empty notes list.
  BenchRecord(const char* bench, const std::string& command_line, const Json& threads)
      : bench_(bench), cpu_(cpu_model()), date_(utc_date()) {
    print_bench_header(bench, command_line, threads_text(threads), cpu_, date_);
    doc_ = {{"command", command_line},
            {"commit", git_commit()},
            {"cpu", cpu_},
            {"hardware_threads", JobSystem::hardware_threads()},
            {"isa", std::string(build_isa())},
            {"date", date_},
            {"load_average_start", load_average()},
            {"threads", threads},
            {"notes", Json::array()}};
  }

  Json& doc() { return doc_; }
  const std::string& cpu() const { return cpu_; }
  const std::string& date() const { return date_; }
  int exit_code() const { return exit_code_; }

  // "sinew-bench BENCH: WHAT: message" on stderr; the run ends with exit code 1.
  void fail(const std::string& what, const Status& status) {
    std::fprintf(stderr, "sinew-bench %s: %s%s%s\n", bench_.c_str(), what.c_str(), what.empty() ? "" : ": ",
                 status.message().c_str());
    exit_code_ = 1;
  }
  // A failure already reported on stdout (a brute-force gate).
  void mark_failed() { exit_code_ = 1; }
  // Printed and kept in the document's notes (an optional model not found).
  void note(const std::string& text) {
    std::printf("\n%s\n", text.c_str());
    doc_["notes"].push_back(text);
  }

  // Writes --json (the document) and --markdown (when given a path); the
  // exit code of the run, 1 when a file could not be written.
  int finish(const std::string& json_path, const std::string& markdown_path = "", const std::string& markdown = "") {
    if (!write_output(bench_.c_str(), "--json", json_path, doc_.dump(2) + "\n")) return 1;
    if (!write_output(bench_.c_str(), "--markdown", markdown_path, markdown)) return 1;
    return exit_code_;
  }

 private:
  static std::string threads_text(const Json& threads) {
    if (!threads.is_array()) return threads.dump();
    std::string out;
    for (const Json& t : threads) out += (out.empty() ? "" : ",") + t.dump();
    return out;
  }

  std::string bench_;
  std::string cpu_;
  std::string date_;
  Json doc_;
  int exit_code_ = 0;
};

// Loads each named model ("mannequin", "cally") and hands it to
// `measure(name, model)`, which returns a Status. A model that is optional
// content and missing becomes a note; an error from loading or measuring is
// reported with the model's name and the loop goes on with the next.
template <class Measure>
void for_each_model(BenchRecord& record, const std::vector<std::string>& names, const std::string& shared,
                    Measure measure) {
  for (const std::string& name : names) {
    std::string missing;
    auto loaded = load_model(name, shared, missing);
    if (!loaded.ok()) {
      record.fail(name, loaded.status());
      continue;
    }
    if (!loaded->has_value()) {
      record.note(missing);
      continue;
    }
    if (const Status s = measure(name, std::move(**loaded)); !s.ok()) record.fail(name, s);
  }
}

}  // namespace sinew::bench
