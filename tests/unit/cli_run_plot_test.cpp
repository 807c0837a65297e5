// `motwin run --plot`: the page it writes holds the run's samples (the same as the CSV trace of
// the same run), carries uPlot and the scope component inline and loads nothing from anywhere;
// a path that cannot be written is a usage error before the run. The page in a browser:
// tests/integration/test_plot_page.py.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "host/web/web_assets.h"
#include "support/host_test_support.h"
#include "support/motwin_cli.h"

namespace motwin {
namespace {

using motwin::testing::run_motwin;
using motwin::testing::ScratchDirectory;

const std::string kStepProgram = std::string(MOTWIN_TEST_PROGRAMS_DIR) + "/tmcm1636_position_step.tmc";

bool contains(std::string_view text, std::string_view part) { return text.find(part) != std::string_view::npos; }

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << path;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The JSON block of a trace page (web/trace/trace.html).
nlohmann::json page_data(const std::string& page) {
  static const std::string kOpen = "<script type=\"application/json\" id=\"motwin-trace-data\">";
  const size_t open = page.find(kOpen);
  if (open == std::string::npos) {
    ADD_FAILURE() << "no data block in the page";
    return {};
  }
  const size_t begin = open + kOpen.size();
  const size_t end = page.find("</script>", begin);
  return nlohmann::json::parse(page.substr(begin, end - begin));
}

struct CsvTrace {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

CsvTrace read_csv(const std::filesystem::path& path) {
  std::istringstream in(read_file(path));
  CsvTrace trace;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream fields_in(line);
    for (std::string field; std::getline(fields_in, field, ',');) fields.push_back(field);
    if (trace.header.empty()) trace.header = fields;
    else trace.rows.push_back(fields);
  }
  return trace;
}

TEST(CliRunPlot, the_page_holds_the_samples_of_the_csv_trace_of_the_same_run) {
  const ScratchDirectory directory;
  const std::filesystem::path page_path = directory.path() / "step.html";
  const std::filesystem::path csv_path = directory.path() / "step.csv";
  const tools::CompletedProcess run =
      run_motwin({"run", kStepProgram, "--module", "tmcm-1636", "--motor", "default-24v", "--for", "200ms", "--sample",
                  "2ms", "--param", "50,52,42,31", "--var", "3", "--trace", csv_path.string(), "--plot", page_path.string()});
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "trace: 101 samples (time_s,AP50,AP52,AP42,AP31,var3) every 2ms to " + csv_path.string()))
      << run.output;
  EXPECT_TRUE(contains(run.output, "plot: 101 samples (time_s,AP50,AP52,AP42,AP31,var3) every 2ms to " + page_path.string()))
      << run.output;

  const std::string page = read_file(page_path);
  const nlohmann::json data = page_data(page);
  const CsvTrace csv = read_csv(csv_path);
  ASSERT_EQ(csv.header.size(), 6u);
  ASSERT_EQ(data["columns"].size(), 5u);
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(data["columns"][i]["name"], csv.header[i + 1]);
  // Names and units from the module's parameter table, for the legend and the axes.
  EXPECT_EQ(data["columns"][1]["label"], "AP52 actual position");
  EXPECT_EQ(data["columns"][1]["unit"], "counts");
  EXPECT_EQ(data["columns"][2]["unit"], "rpm");
  EXPECT_EQ(data["columns"][3]["unit"], "mA");
  EXPECT_EQ(data["columns"][4]["label"], "var3 (user variable 3)");

  ASSERT_EQ(csv.rows.size(), 101u);
  ASSERT_EQ(data["time_s"].size(), csv.rows.size());
  for (size_t k = 0; k < csv.rows.size(); ++k) {
    SCOPED_TRACE("row " + std::to_string(k));
    EXPECT_EQ(data["time_s"][k].get<double>(), std::stod(csv.rows[k][0]));
    for (size_t i = 0; i < 5; ++i) EXPECT_EQ(data["values"][i][k].get<int64_t>(), std::stoll(csv.rows[k][i + 1]));
  }
  // A step response indeed: the target jumps, the position follows and moves in between.
  EXPECT_EQ(data["values"][0][100], 4000);
  EXPECT_GT(data["values"][1][10].get<int64_t>(), 0);
  EXPECT_LT(data["values"][1][10].get<int64_t>(), 4000);

  EXPECT_EQ(data["module"], "tmcm-1636");
  EXPECT_EQ(data["firmware"], "1636V109");
  EXPECT_EQ(data["program"], kStepProgram);
  EXPECT_EQ(data["duration_s"], 0.2);
  EXPECT_EQ(data["sample_s"], 0.002);
  EXPECT_TRUE(std::regex_match(data["started_utc"].get<std::string>(),
                               std::regex(R"(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d UTC)")))
      << data["started_utc"];
  EXPECT_TRUE(contains(data["report"].get<std::string>(), "program: stopped by t=")) << data["report"];
  EXPECT_TRUE(contains(page, "<title>tmcm1636_position_step.tmc on tmcm-1636, ")) << page.substr(0, 2000);
  // Written through a temporary file: nothing else is left in the directory.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(directory.path()), std::filesystem::directory_iterator()),
            2);
}

TEST(CliRunPlot, the_page_embeds_uplot_with_its_licence_and_loads_nothing_from_the_network) {
  const ScratchDirectory directory;
  const std::filesystem::path page_path = directory.path() / "page.html";
  const tools::CompletedProcess run =
      run_motwin({"run", kStepProgram, "--for", "20ms", "--sample", "1ms", "--plot", page_path.string()});
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const std::string page = read_file(page_path);
  for (const char* key : {"vendor/uPlot.iife.min.js", "vendor/uPlot.min.css", "site/scope.js", "site/scope.css",
                          "trace/trace.js"}) {
    const std::optional<host::web::WebAsset> asset = host::web::find_web_asset(key);
    ASSERT_TRUE(asset.has_value()) << key;
    EXPECT_TRUE(contains(page, asset->bytes)) << key << " is not in the page as it is";
  }
  EXPECT_TRUE(contains(page, "The MIT License (MIT)"));
  EXPECT_TRUE(contains(page, "Copyright (c) 2022 Leon Sorokin"));
  // Nothing refers outside the page: no src or href with a scheme or protocol-relative URL
  // anywhere (markup or script), and the markup's only reference is the favicon's data: URL.
  EXPECT_FALSE(std::regex_search(page, std::regex(R"((src|href)\s*=\s*["']?\s*([a-z]+:)?//)", std::regex::icase)));
  const std::regex tag_reference(R"(<(script|link|img|iframe|a|source|embed|object|audio|video)\b[^>]*\b(src|href)\s*=\s*["']?([^"'\s>]*))",
                                 std::regex::icase);
  size_t references = 0;
  for (auto it = std::sregex_iterator(page.begin(), page.end(), tag_reference); it != std::sregex_iterator(); ++it) {
    ++references;
    EXPECT_EQ((*it)[3].str().rfind("data:", 0), 0u) << "the page refers to " << (*it)[0];
  }
  EXPECT_EQ(references, 1u) << "the favicon only";
  EXPECT_FALSE(std::regex_search(page, std::regex(R"(url\(\s*['"]?\s*(https?:)?//)", std::regex::icase)));
  EXPECT_FALSE(contains(page, "@import"));
  // Every script is inline: no <script src=...>.
  EXPECT_FALSE(std::regex_search(page, std::regex(R"(<script[^>]*\bsrc\s*=)", std::regex::icase)));
  // The placeholders are all filled.
  EXPECT_FALSE(contains(page, "@MOTWIN_"));
  // --plot alone writes no CSV, and the report says where the page went.
  EXPECT_FALSE(contains(run.output, "trace:")) << run.output;
  EXPECT_TRUE(contains(run.output, "plot: 21 samples (time_s,AP52,AP42) every 1ms to " + page_path.string()))
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(directory.path() / "trace.csv"));
}

TEST(CliRunPlot, a_path_that_cannot_be_written_is_a_usage_error_before_the_run) {
  const ScratchDirectory directory;
  const std::string missing = (directory.path() / "no-such-dir" / "page.html").string();
  const tools::CompletedProcess run = run_motwin({"run", kStepProgram, "--for", "1s", "--plot", missing});
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_TRUE(contains(run.output, "motwin: error: --plot: cannot write " + missing + ": No such file or directory"))
      << run.output;
  EXPECT_FALSE(contains(run.output, "simulated time")) << "refused before the run: " << run.output;

  const tools::CompletedProcess directory_run =
      run_motwin({"run", kStepProgram, "--for", "1s", "--plot", directory.path().string()});
  EXPECT_EQ(directory_run.exit_status, 2) << directory_run.output;
  EXPECT_TRUE(contains(directory_run.output, "--plot: cannot write " + directory.path().string() + ": Is a directory"))
      << directory_run.output;
  EXPECT_TRUE(std::filesystem::is_empty(directory.path()));

  const tools::CompletedProcess to_stdout = run_motwin({"run", kStepProgram, "--for", "1s", "--plot", "-"});
  EXPECT_EQ(to_stdout.exit_status, 2) << to_stdout.output;
  EXPECT_TRUE(contains(to_stdout.output, "motwin: error: --plot -: the page goes to a file")) << to_stdout.output;
}

}  // namespace
}  // namespace motwin
