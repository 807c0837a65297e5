// The self-contained HTML page of a traced run (`motwin run --plot`): the template
// web/trace/trace.html with uPlot, its licence, the scope component (web/site/scope.js, .css) and
// the page script inlined from the embedded assets (web_assets.h), and the run's data as one JSON
// block. docs/web-console.md "Trace pages" describes the page and its JSON.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "types/result.h"

namespace motwin::host::web {

struct TraceColumn {
  std::string name;   // as the CSV header says it: "AP52", "var0"
  std::string label;  // for the legend: "AP52 actual position"
  std::string unit;   // "counts", "rpm"; empty when dimensionless
};

struct TracePageData {
  std::string title;        // the page's heading and <title>
  std::string module;       // "tmcm-1636"
  std::string firmware;     // "1636V109"
  std::string program;      // the program file as given
  std::string started_utc;  // "2026-11-27 02:40:00 UTC"
  double duration_s = 0;    // simulated time run
  double sample_s = 0;      // sample period
  std::string report;       // what `motwin run` reported after the run
  std::vector<TraceColumn> columns;
  std::vector<double> time_s;                // one per sample
  std::vector<std::vector<int64_t>> values;  // per column, one per sample
};

// The data block of the page: {"title", "module", ..., "columns": [{"name", "label", "unit"}],
// "time_s": [...], "values": [[...], ...]}; '<' is written as \u003c so that no text in it can
// end the <script> element that holds it.
std::string trace_data_json(const TracePageData& data);

// The whole page; an error only when an embedded asset is missing (a build without them).
Result<std::string> render_trace_page(const TracePageData& data);

}  // namespace motwin::host::web
