// The trace page renderer (src/host/web/trace_page.h) and the atomic file it is written through
// (src/host/atomic_file.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "host/atomic_file.h"
#include "host/web/trace_page.h"
#include "support/host_test_support.h"

namespace motwin::host {
namespace {

using motwin::testing::ScratchDirectory;

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

size_t entries(const std::filesystem::path& directory) {
  return static_cast<size_t>(
      std::distance(std::filesystem::directory_iterator(directory), std::filesystem::directory_iterator()));
}

web::TracePageData sample_data() {
  web::TracePageData data;
  data.title = "a </script><b>bold</b> & \"quoted\" title";
  data.module = "tmcm-1636";
  data.program = "</script><script>alert(1)</script>.tmc";
  data.columns = {{"AP52", "AP52 actual position", "counts"}, {"var0", "var0", ""}};
  data.time_s = {0.0, 0.001, 0.002};
  data.values = {{0, 10, -20}, {1, 2, 3}};
  return data;
}

TEST(TracePage, text_from_the_run_cannot_break_out_of_the_page) {
  const Result<std::string> page = web::render_trace_page(sample_data());
  ASSERT_TRUE(page) << page.error();
  EXPECT_NE(page->find("<title>a &lt;/script&gt;&lt;b&gt;bold&lt;/b&gt; &amp; &quot;quoted&quot; title</title>"),
            std::string::npos);
  EXPECT_EQ(page->find("<script>alert(1)"), std::string::npos);
  EXPECT_EQ(page->find("<b>bold"), std::string::npos);
  // The JSON block still says the same: \u003c is '<' to JSON.parse.
  const std::string json = web::trace_data_json(sample_data());
  EXPECT_EQ(json.find('<'), std::string::npos);
  const nlohmann::json parsed = nlohmann::json::parse(json);
  EXPECT_EQ(parsed["program"], "</script><script>alert(1)</script>.tmc");
  EXPECT_EQ(parsed["values"][0][2], -20);
  EXPECT_EQ(parsed["time_s"][1], 0.001);
  EXPECT_EQ(parsed["columns"][0]["unit"], "counts");
}

TEST(AtomicFile, the_file_appears_whole_on_commit_and_never_without_it) {
  const ScratchDirectory directory;
  const std::filesystem::path path = directory.path() / "page.html";
  {
    std::ofstream(path) << "old";
    Result<AtomicFile> file = AtomicFile::create(path.string());
    ASSERT_TRUE(file) << file.error();
    EXPECT_EQ(entries(directory.path()), 2u) << "the temporary file beside it";
    EXPECT_EQ(read_file(path), "old");
  }
  EXPECT_EQ(read_file(path), "old") << "dropped without commit: the old file stays";
  EXPECT_EQ(entries(directory.path()), 1u) << "and the temporary file is gone";

  Result<AtomicFile> file = AtomicFile::create(path.string());
  ASSERT_TRUE(file) << file.error();
  ASSERT_TRUE(file->commit("new contents"));
  EXPECT_EQ(read_file(path), "new contents");
  EXPECT_EQ(entries(directory.path()), 1u);
  EXPECT_FALSE(file->commit("again")) << "one commit per file";
}

TEST(AtomicFile, a_missing_directory_fails_at_create_with_the_reason) {
  const Result<AtomicFile> file = AtomicFile::create("/nonexistent-motwin-dir/page.html");
  ASSERT_FALSE(file);
  EXPECT_EQ(file.error(), "cannot write /nonexistent-motwin-dir/page.html: No such file or directory");
}

}  // namespace
}  // namespace motwin::host
