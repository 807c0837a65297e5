#include "host/web/web_assets.h"

#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace motwin::host::web {
namespace {

std::string read_source_file(const std::string& path_below_src) {
  std::ifstream in(std::string(MOTWIN_SOURCE_DIR) + "/../" + path_below_src, std::ios::binary);
  EXPECT_TRUE(in.good()) << path_below_src;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(WebAssets, the_plotting_library_is_embedded_byte_for_byte_from_the_pinned_npm_package) {
  const auto script = find_web_asset("vendor/uPlot.iife.min.js");
  ASSERT_TRUE(script.has_value());
  EXPECT_EQ(script->bytes, read_source_file("web/node_modules/uplot/dist/uPlot.iife.min.js"));
  EXPECT_EQ(script->content_type, "text/javascript; charset=utf-8");
  // The version web/package-lock.json pins (uPlot's banner names it).
  EXPECT_NE(script->bytes.substr(0, 80).find("(v1.6.32)"), std::string_view::npos) << script->bytes.substr(0, 80);

  const auto style = find_web_asset("vendor/uPlot.min.css");
  ASSERT_TRUE(style.has_value());
  EXPECT_EQ(style->content_type, "text/css; charset=utf-8");
  EXPECT_EQ(style->bytes, read_source_file("web/node_modules/uplot/dist/uPlot.min.css"));
  // Its licence travels with it.
  const auto licence = find_web_asset("vendor/uPlot.LICENSE.txt");
  ASSERT_TRUE(licence.has_value());
  EXPECT_NE(licence->bytes.find("MIT"), std::string_view::npos);
}

TEST(WebAssets, each_file_ends_in_a_nul_so_text_can_be_handed_to_c_apis) {
  for (const EmbeddedFile& file : embedded_files()) EXPECT_EQ(file.bytes[file.size], 0) << file.key;
}

TEST(WebAssets, keys_are_unique_and_unknown_keys_find_nothing) {
  std::set<std::string> keys;
  for (const EmbeddedFile& file : embedded_files()) EXPECT_TRUE(keys.insert(file.key).second) << file.key;
  EXPECT_FALSE(find_web_asset("vendor/missing.js").has_value());
  EXPECT_FALSE(find_web_asset("").has_value());
  EXPECT_FALSE(find_web_asset("/vendor/uPlot.iife.min.js").has_value());  // keys have no leading slash
}

TEST(WebAssets, content_types_follow_the_extension) {
  EXPECT_EQ(content_type_for("site/index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(content_type_for("site/favicon.svg"), "image/svg+xml");
  EXPECT_EQ(content_type_for("site/data.bin"), "application/octet-stream");
}

}  // namespace
}  // namespace motwin::host::web
