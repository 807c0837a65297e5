// The script of a trace page (web/trace/trace.html): reads the run's data from the page's
// JSON block and plots it with the scope component. `window.motwinPlot` gives scripts and the
// browser tests the data, the scope and its uPlot instance.
(function () {
  "use strict";
  const trace = JSON.parse(document.getElementById("motwin-trace-data").textContent);
  const meta = document.getElementById("trace-meta");
  const facts = [
    ["module", trace.module + (trace.firmware ? " (" + trace.firmware + ")" : "")],
    ["program", trace.program],
    ["run", trace.started_utc],
    ["simulated", trace.duration_s + " s"],
    ["sample", trace.sample_s + " s"],
    ["samples", String(trace.time_s.length)],
  ];
  for (const [name, value] of facts) {
    const item = document.createElement("span");
    item.textContent = name + ": " + value;
    meta.appendChild(item);
  }
  document.getElementById("trace-report").textContent = trace.report || "";
  const scope = MotwinScope.create(document.getElementById("trace-plot"), {
    title: trace.title,
    showTitle: false,  // the page's heading says it
    series: trace.columns.map((c) => ({name: c.name, label: c.label, unit: c.unit})),
    windowSeconds: null,
  });
  scope.setData(trace.time_s, trace.values);
  window.motwinPlot = {trace: trace, scope: scope, uplot: scope.uplot};
})();
