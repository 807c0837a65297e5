#include "host/web/trace_page.h"

#include <map>
#include <string_view>

#include <nlohmann/json.hpp>

#include "host/web/web_assets.h"

namespace motwin::host::web {
namespace {

using OrderedJson = nlohmann::ordered_json;

// Text for HTML element content and attribute values.
std::string escape_html(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      case '\'': escaped += "&#39;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

// Script or style text placed inside its element: "</" becomes "<\/" so that it cannot close
// the element early (the embedded files hold none today; this keeps it so).
std::string inline_text(std::string_view text) {
  std::string safe;
  safe.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    safe += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') safe += '\\';
  }
  return safe;
}

// Fills @MOTWIN_NAME@ in one pass over the template: inserted text is never searched again.
Result<std::string> fill_template(std::string_view page, const std::map<std::string, std::string, std::less<>>& values) {
  static constexpr std::string_view kOpen = "@MOTWIN_";
  std::string filled;
  filled.reserve(page.size());
  size_t at = 0;
  while (true) {
    const size_t open = page.find(kOpen, at);
    if (open == std::string_view::npos) break;
    const size_t close = page.find('@', open + 1);
    if (close == std::string_view::npos) break;
    const std::string_view name = page.substr(open + 1, close - open - 1);
    const auto found = values.find(name);
    if (found == values.end()) return Error{"trace page template: unknown placeholder @" + std::string(name) + "@"};
    filled.append(page.substr(at, open - at));
    filled += found->second;
    at = close + 1;
  }
  filled.append(page.substr(at));
  return filled;
}

}  // namespace

std::string trace_data_json(const TracePageData& data) {
  OrderedJson json;
  json["title"] = data.title;
  json["module"] = data.module;
  json["firmware"] = data.firmware;
  json["program"] = data.program;
  json["started_utc"] = data.started_utc;
  json["duration_s"] = data.duration_s;
  json["sample_s"] = data.sample_s;
  json["report"] = data.report;
  OrderedJson columns = OrderedJson::array();
  for (const TraceColumn& column : data.columns) {
    columns.push_back(OrderedJson{{"name", column.name}, {"label", column.label}, {"unit", column.unit}});
  }
  json["columns"] = std::move(columns);
  json["time_s"] = data.time_s;
  json["values"] = data.values;
  // Invalid UTF-8 in a name (a program path) is replaced rather than aborting the dump.
  const std::string text = json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string safe;
  safe.reserve(text.size());
  for (const char c : text) {
    if (c == '<') safe += "\\u003c";  // only inside strings in JSON, where the escape means the same
    else safe += c;
  }
  return safe;
}

Result<std::string> render_trace_page(const TracePageData& data) {
  static constexpr std::string_view kAssets[][2] = {
      {"MOTWIN_UPLOT_CSS", "vendor/uPlot.min.css"},   {"MOTWIN_UPLOT_JS", "vendor/uPlot.iife.min.js"},
      {"MOTWIN_UPLOT_LICENSE", "vendor/uPlot.LICENSE.txt"}, {"MOTWIN_SCOPE_CSS", "site/scope.css"},
      {"MOTWIN_SCOPE_JS", "site/scope.js"},           {"MOTWIN_TRACE_JS", "trace/trace.js"},
  };
  const std::optional<WebAsset> page = find_web_asset("trace/trace.html");
  if (!page) return Error{"this motwin was built without its trace page template (trace/trace.html)"};
  std::map<std::string, std::string, std::less<>> values;
  for (const auto& [name, key] : kAssets) {
    const std::optional<WebAsset> asset = find_web_asset(key);
    if (!asset) return Error{"this motwin was built without " + std::string(key)};
    std::string text = inline_text(asset->bytes);
    // The licence sits in a /* */ comment: keep any "*/" in it from closing that early.
    if (name == "MOTWIN_UPLOT_LICENSE") {
      for (size_t at = text.find("*/"); at != std::string::npos; at = text.find("*/", at)) text.replace(at, 2, "* /");
    }
    values.emplace(std::string(name), std::move(text));
  }
  values.emplace("MOTWIN_TITLE", escape_html(data.title));
  values.emplace("MOTWIN_TRACE_DATA", trace_data_json(data));
  return fill_template(page->bytes, values);
}

}  // namespace motwin::host::web
