// MotwinScope: curves against time on uPlot, for the web console's Scope view (live samples)
// and for the trace pages `motwin run --plot` writes (a whole run at once). Plain script, no build
// step: it needs the global `uPlot` (/vendor/uPlot.iife.min.js) loaded before it, and defines the
// global `MotwinScope`. docs/web-console.md "The scope component" documents the API.
//
//   const scope = MotwinScope.create(container, {
//     series: [{name: "AP52", label: "actual position", unit: "counts"}, ...],
//     windowSeconds: 10,   // live: the last 10 s scroll by; null: everything (trace pages)
//   });
//   scope.push(time_s, [v0, v1, ...]);   // as often as samples come; redraws once per frame
(function (global) {
  "use strict";

  const kPalette = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"];
  const kDefaultCapacity = 200000;  // points kept per curve (ring buffer)
  const kPngLineHeightCss = 18;      // one line of text below the plot in exportPng, CSS pixels
  const kDefaultPreTrigger = 0.25;   // part of the window before the trigger point

  // 1234, 12.5, 0.000123: integers as they are, other numbers to 6 significant digits.
  function formatNumber(value) {
    if (value == null || Number.isNaN(value)) return "–";
    if (Number.isInteger(value)) return String(value);
    return String(Number(value.toPrecision(6)));
  }

  function withUnit(text, unit) {
    return unit ? text + " " + unit : text;
  }

  // Points in time order, oldest first, with a fixed capacity: the oldest are dropped.
  class RingBuffer {
    constructor(seriesCount, capacity) {
      this.capacity = capacity;
      this.times = new Float64Array(capacity);
      this.values = [];
      for (let i = 0; i < seriesCount; i++) this.values.push(new Float64Array(capacity));
      this.start = 0;
      this.count = 0;
    }

    clear() {
      this.start = 0;
      this.count = 0;
    }

    slot(index) {
      return (this.start + index) % this.capacity;
    }

    push(time, values) {
      let slot;
      if (this.count < this.capacity) {
        slot = this.slot(this.count);
        this.count++;
      } else {
        slot = this.start;
        this.start = (this.start + 1) % this.capacity;
      }
      this.times[slot] = time;
      for (let i = 0; i < this.values.length; i++) {
        const value = values[i];
        this.values[i][slot] = value == null ? NaN : Number(value);
      }
    }

    time(index) {
      return this.times[this.slot(index)];
    }

    value(series, index) {
      return this.values[series][this.slot(index)];
    }

    lastTime() {
      return this.count > 0 ? this.time(this.count - 1) : null;
    }

    // The first index whose time is >= t (count when none).
    lowerBound(t) {
      let low = 0;
      let high = this.count;
      while (low < high) {
        const middle = (low + high) >> 1;
        if (this.time(middle) < t) low = middle + 1;
        else high = middle;
      }
      return low;
    }

    // uPlot's data ([times, curve0, curve1 ...]) for the points from..to-1, NaN as null (a gap).
    columns(from, to) {
      const length = Math.max(0, to - from);
      const times = new Array(length);
      const curves = this.values.map(() => new Array(length));
      for (let k = 0; k < length; k++) {
        const slot = this.slot(from + k);
        times[k] = this.times[slot];
        for (let i = 0; i < curves.length; i++) {
          const value = this.values[i][slot];
          curves[i][k] = Number.isNaN(value) ? null : value;
        }
      }
      return [times].concat(curves);
    }
  }

  function button(text, title, onClick) {
    const element = document.createElement("button");
    element.type = "button";
    element.textContent = text;
    element.title = title;
    element.addEventListener("click", onClick);
    return element;
  }

  function download(fileName, url) {
    const link = document.createElement("a");
    link.href = url;
    link.download = fileName;
    document.body.appendChild(link);
    link.click();
    link.remove();
  }

  class Scope {
    constructor(container, options) {
      if (typeof global.uPlot !== "function") throw new Error("MotwinScope needs uPlot: load uPlot.iife.min.js first");
      if (!options || !Array.isArray(options.series) || options.series.length === 0) {
        throw new Error("MotwinScope.create: options.series must list at least one curve");
      }
      this.container = container;
      this.series = options.series.map((s, i) => ({
        name: s.name || s.label || "y" + i,
        label: s.label || s.name || "y" + i,
        unit: s.unit || "",
        color: s.color || kPalette[i % kPalette.length],
      }));
      this.windowSeconds = options.windowSeconds > 0 ? options.windowSeconds : null;
      this.title = options.title || "";  // the plot's heading, the PNG's first line, the file names
      this.showTitle = options.showTitle !== false;
      this.fixedHeight = options.height || null;
      this.buffer = new RingBuffer(this.series.length, options.capacity || kDefaultCapacity);
      this.paused = false;
      this.zoomRange = null;        // [min, max] the user zoomed to, or null
      this.trigger = null;          // {series, level, edge, mode, pre, windowSeconds}
      this.triggerState = "off";    // off | armed | capturing | triggered
      this.triggerTime = null;
      this.frozen = null;           // uPlot data of the captured trigger window
      this.frozenRange = null;
      this.frameRequested = false;
      this.counters = {pushes: 0, redraws: 0, lastDrawnTime: null};

      this.root = document.createElement("div");
      this.root.className = "motwin-scope";
      container.appendChild(this.root);
      if (options.toolbar !== false) this.buildToolbar();
      this.plotElement = document.createElement("div");
      this.plotElement.className = "motwin-scope-plot";
      this.root.appendChild(this.plotElement);

      this.uplot = new global.uPlot(this.plotOptions(), [[]].concat(this.series.map(() => [])), this.plotElement);
      this.resizeObserver = new ResizeObserver(() => this.fitSize());
      this.resizeObserver.observe(this.root);
      this.updateStatus();
    }

    // --- uPlot options ----------------------------------------------------------------------

    plotOptions() {
      const self = this;
      // One y scale and axis per unit: curves of the same unit share it; the first unit's axis
      // is on the left, the second on the right, more alternate outward.
      const units = [];
      this.series.forEach((s) => {
        if (!units.includes(s.unit)) units.push(s.unit);
      });
      const scales = {x: {time: false}};
      const axes = [{
        label: "time (s)",
        stroke: "#333",
        grid: {stroke: "#e4e4e4"},
        ticks: {stroke: "#ccc"},
      }];
      units.forEach((unit, i) => {
        const key = "unit:" + unit;
        scales[key] = {auto: true};
        const first = this.series.find((s) => s.unit === unit);
        const sameUnit = this.series.filter((s) => s.unit === unit);
        axes.push({
          scale: key,
          side: i % 2 === 0 ? 3 : 1,
          label: unit || (sameUnit.length === 1 ? first.label : ""),
          stroke: sameUnit.length === 1 ? first.color : "#333",
          grid: {show: i === 0, stroke: "#e4e4e4"},
          ticks: {stroke: "#ccc"},
          size: 60,
          values: (u, splits) => splits.map(formatNumber),
        });
      });
      const series = [{label: "time", value: (u, v) => (v == null ? "–" : formatNumber(v) + " s")}];
      this.series.forEach((s) => {
        series.push({
          label: s.label,
          scale: "unit:" + s.unit,
          stroke: s.color,
          width: 1.5,
          points: {show: false},
          spanGaps: false,
          value: (u, v) => (v == null ? "–" : withUnit(formatNumber(v), s.unit)),
        });
      });
      const size = this.plotSize();
      return {
        title: this.showTitle && this.title ? this.title : undefined,
        width: size.width,
        height: size.height,
        scales: scales,
        axes: axes,
        series: series,
        legend: {live: true},
        cursor: {
          drag: {x: true, y: false, setScale: true},
          // uPlot resets x to the data on a double click; the scope then goes back to its live
          // window (or to the whole trace) and forgets the zoom.
          bind: {
            dblclick: (u, target, handler) => (e) => {
              handler(e);
              self.resetZoom();
              return null;
            },
          },
        },
        hooks: {
          // A drag selected a range: uPlot zooms to it right after this hook.
          setSelect: [(u) => {
            if (u.select.width <= 0) return;
            const min = u.posToVal(u.select.left, "x");
            const max = u.posToVal(u.select.left + u.select.width, "x");
            if (max > min) self.zoomRange = [min, max];
            self.updateStatus();
          }],
          draw: [(u) => self.drawTriggerMarks(u)],
        },
      };
    }

    plotSize() {
      const width = Math.max(200, Math.floor(this.root.clientWidth || this.container.clientWidth || 800));
      let height = this.fixedHeight;
      if (!height) height = Math.max(180, Math.min(480, Math.floor(global.innerHeight * 0.6)));
      return {width: width, height: height};
    }

    fitSize() {
      const size = this.plotSize();
      if (size.width !== this.uplot.width || size.height !== this.uplot.height) this.uplot.setSize(size);
    }

    // The trigger time (dashed vertical) and level (dashed horizontal, on its curve's scale).
    drawTriggerMarks(u) {
      if (!this.trigger) return;
      const ctx = u.ctx;
      const s = this.series[this.trigger.series];
      ctx.save();
      ctx.setLineDash([6, 4]);
      ctx.lineWidth = 1;
      ctx.strokeStyle = s.color;
      const y = u.valToPos(this.trigger.level, "unit:" + s.unit, true);
      if (Number.isFinite(y) && y >= u.bbox.top && y <= u.bbox.top + u.bbox.height) {
        ctx.beginPath();
        ctx.moveTo(u.bbox.left, y);
        ctx.lineTo(u.bbox.left + u.bbox.width, y);
        ctx.stroke();
      }
      if (this.triggerTime != null) {
        const x = u.valToPos(this.triggerTime, "x", true);
        if (Number.isFinite(x) && x >= u.bbox.left && x <= u.bbox.left + u.bbox.width) {
          ctx.strokeStyle = "#555";
          ctx.beginPath();
          ctx.moveTo(x, u.bbox.top);
          ctx.lineTo(x, u.bbox.top + u.bbox.height);
          ctx.stroke();
        }
      }
      ctx.restore();
    }

    // --- The toolbar (optional) --------------------------------------------------------------

    buildToolbar() {
      const bar = document.createElement("div");
      bar.className = "motwin-scope-toolbar";
      const controls = {};
      if (this.windowSeconds) {
        controls.pause = button("Pause", "Stop redrawing; samples are still kept", () => this.setPaused(!this.paused));
        bar.appendChild(controls.pause);
      }
      controls.reset = button("Reset zoom", "Back to the whole view (or double-click the plot)", () => this.resetZoom());
      bar.appendChild(controls.reset);

      const triggerGroup = document.createElement("span");
      triggerGroup.className = "motwin-scope-trigger";
      const seriesSelect = document.createElement("select");
      seriesSelect.title = "Trigger on this curve";
      this.series.forEach((s, i) => seriesSelect.add(new Option(s.label, String(i))));
      const level = document.createElement("input");
      level.type = "number";
      level.step = "any";
      level.value = "0";
      level.title = "Trigger level, in the curve's unit";
      level.setAttribute("aria-label", "trigger level");
      const edge = document.createElement("select");
      edge.title = "Edge";
      edge.add(new Option("rising", "rising"));
      edge.add(new Option("falling", "falling"));
      const mode = document.createElement("select");
      mode.title = "Single: freeze on the first crossing. Normal: re-arm after each capture";
      mode.add(new Option("single", "single"));
      mode.add(new Option("normal", "normal"));
      const arm = button("Trigger", "Arm the trigger (on a trace: show the first crossing)", () => {
        this.setTrigger({
          series: Number(seriesSelect.value),
          level: Number(level.value),
          edge: edge.value,
          mode: mode.value,
        });
      });
      const off = button("Off", "Trigger off", () => this.setTrigger(null));
      const label = document.createElement("span");
      label.textContent = "Trigger";
      triggerGroup.append(label, seriesSelect, edge, level, mode, arm, off);
      bar.appendChild(triggerGroup);

      const baseName = (this.title || "scope").replace(/[^A-Za-z0-9._-]+/g, "_").slice(0, 80);
      controls.csv = button("CSV", "Save the curves as CSV", () => {
        const url = URL.createObjectURL(new Blob([this.exportCsv()], {type: "text/csv"}));
        download(baseName + ".csv", url);
        setTimeout(() => URL.revokeObjectURL(url), 0);
      });
      controls.png = button("PNG", "Save the plot as an image", () => download(baseName + ".png", this.exportPng()));
      bar.append(controls.csv, controls.png);
      this.status = document.createElement("span");
      this.status.className = "motwin-scope-status";
      this.status.setAttribute("role", "status");
      bar.appendChild(this.status);
      this.controls = controls;
      this.root.appendChild(bar);
    }

    updateStatus() {
      if (this.controls && this.controls.pause) this.controls.pause.textContent = this.paused ? "Run" : "Pause";
      if (!this.status) return;
      const parts = [];
      if (this.paused) parts.push("paused");
      if (this.zoomRange) parts.push("zoomed");
      if (this.triggerState !== "off") {
        let text = "trigger " + this.triggerState;
        if (this.triggerTime != null && this.triggerState !== "armed") text += " at " + formatNumber(this.triggerTime) + " s";
        parts.push(text);
      }
      this.status.textContent = parts.join(", ");
    }

    // --- Data ---------------------------------------------------------------------------------

    // One sample of every curve at time_s (seconds); a value null or missing leaves a gap.
    // Time going backwards (a module restarted) starts the curves afresh.
    push(time_s, values) {
      const last = this.buffer.lastTime();
      if (last != null && time_s < last) this.clear();
      const previous = this.trigger && this.buffer.count > 0 ? this.buffer.value(this.trigger.series, this.buffer.count - 1) : null;
      this.buffer.push(time_s, values || []);
      this.counters.pushes++;
      if (this.trigger) this.checkTrigger(previous, time_s);
      this.requestRedraw();
    }

    // Replaces every curve: times [t0, t1 ...] and columns [[curve0 ...], [curve1 ...]].
    setData(times, columns) {
      if (times.length > this.buffer.capacity) this.buffer = new RingBuffer(this.series.length, times.length);
      this.buffer.clear();
      const row = new Array(this.series.length);
      for (let k = 0; k < times.length; k++) {
        for (let i = 0; i < row.length; i++) row[i] = columns[i] ? columns[i][k] : null;
        this.buffer.push(times[k], row);
      }
      this.zoomRange = null;
      this.frozen = null;
      if (this.trigger) this.setTrigger(this.trigger);
      this.redraw();
    }

    clear() {
      this.buffer.clear();
      this.frozen = null;
      this.frozenRange = null;
      if (this.trigger) this.arm();
      this.requestRedraw();
    }

    setPaused(paused) {
      this.paused = Boolean(paused);
      this.updateStatus();
      if (!this.paused) this.requestRedraw();
    }

    isPaused() {
      return this.paused;
    }

    zoom(min_s, max_s) {
      if (!(max_s > min_s)) return;
      this.zoomRange = [min_s, max_s];
      this.redraw();
    }

    resetZoom() {
      this.zoomRange = null;
      this.updateStatus();
      this.redraw();
    }

    // --- Trigger ------------------------------------------------------------------------------

    // {series: index, level, edge: "rising"|"falling", mode: "single"|"normal",
    //  pre: part of the window before the crossing (0.25), windowSeconds: the captured span}.
    // null turns it off. Live, it arms for the coming samples; on data loaded with setData it
    // shows the first crossing at once. The crossing is the first sample at or past the level.
    setTrigger(options) {
      this.frozen = null;
      this.frozenRange = null;
      this.triggerTime = null;
      if (!options) {
        this.trigger = null;
        this.triggerState = "off";
        this.updateStatus();
        this.redraw();
        return;
      }
      const series = Number(options.series || 0);
      if (!(series >= 0 && series < this.series.length)) throw new Error("setTrigger: no curve " + options.series);
      const pre = options.pre != null ? Math.min(1, Math.max(0, Number(options.pre))) : kDefaultPreTrigger;
      this.trigger = {
        series: series,
        level: Number(options.level),
        edge: options.edge === "falling" ? "falling" : "rising",
        mode: options.mode === "normal" ? "normal" : "single",
        pre: pre,
        windowSeconds: options.windowSeconds > 0 ? Number(options.windowSeconds) : null,
      };
      if (this.windowSeconds) {
        this.arm();
      } else {
        this.findTriggerInData();
      }
    }

    // Live: wait for the next crossing (after a single-shot capture, or to restart one).
    arm() {
      if (!this.trigger) return;
      this.triggerState = "armed";
      this.triggerTime = null;
      this.updateStatus();
      this.requestRedraw();
    }

    triggerStatus() {
      return {state: this.triggerState, time_s: this.triggerTime};
    }

    crosses(previous, value) {
      if (previous == null || Number.isNaN(previous) || Number.isNaN(value)) return false;
      const level = this.trigger.level;
      return this.trigger.edge === "rising" ? previous < level && value >= level : previous > level && value <= level;
    }

    spanOf(trigger) {
      if (trigger.windowSeconds) return trigger.windowSeconds;
      if (this.windowSeconds) return this.windowSeconds;
      const range = this.visibleRange();
      return range ? range[1] - range[0] : 1;
    }

    checkTrigger(previous, time_s) {
      const t = this.trigger;
      if (this.triggerState === "armed" && this.crosses(previous, this.buffer.value(t.series, this.buffer.count - 1))) {
        this.triggerState = "capturing";
        this.pendingTriggerTime = time_s;
        this.updateStatus();
      }
      if (this.triggerState === "capturing") {
        const span = this.spanOf(t);
        const from = this.pendingTriggerTime - span * t.pre;
        const to = this.pendingTriggerTime + span * (1 - t.pre);
        if (time_s >= to) this.freeze(this.pendingTriggerTime, from, to);
      }
    }

    freeze(trigger_s, from_s, to_s) {
      const first = Math.max(0, this.buffer.lowerBound(from_s) - 1);
      const last = Math.min(this.buffer.count, this.buffer.lowerBound(to_s) + 1);
      this.frozen = this.buffer.columns(first, last);
      this.frozenRange = [from_s, to_s];
      this.triggerTime = trigger_s;
      this.zoomRange = null;
      // Normal mode shows this capture until the next one completes.
      this.triggerState = this.trigger.mode === "normal" ? "armed" : "triggered";
      this.updateStatus();
      if (!this.paused) this.redraw();
    }

    // On loaded data: the first crossing, shown with its pre-trigger part.
    findTriggerInData() {
      const t = this.trigger;
      const span = this.spanOf(t);
      for (let k = 1; k < this.buffer.count; k++) {
        if (this.crosses(this.buffer.value(t.series, k - 1), this.buffer.value(t.series, k))) {
          const time = this.buffer.time(k);
          this.trigger.mode = "single";
          this.freeze(time, time - span * t.pre, time + span * (1 - t.pre));
          return;
        }
      }
      this.triggerState = "armed";  // no crossing in the data
      this.updateStatus();
      this.redraw();
    }

    // --- Drawing ------------------------------------------------------------------------------

    requestRedraw() {
      if (this.paused || this.frameRequested) return;
      this.frameRequested = true;
      global.requestAnimationFrame(() => {
        this.frameRequested = false;
        if (!this.paused) this.redraw();
      });
    }

    // The x range the view shows: a zoom, a trigger capture, the live window or everything.
    visibleRange() {
      if (this.zoomRange) return this.zoomRange;
      if (this.frozenRange) return this.frozenRange;
      if (this.buffer.count === 0) return null;
      const last = this.buffer.lastTime();
      if (this.windowSeconds) return [last - this.windowSeconds, last];
      const first = this.buffer.time(0);
      return first < last ? [first, last] : [first - 0.5, last + 0.5];
    }

    // What the plot is given: the captured window, or the buffered points in view (one more on
    // each side, so the curve runs to the edges).
    viewData() {
      if (this.frozen) return this.frozen;
      const range = this.visibleRange();
      if (!range) return [[]].concat(this.series.map(() => []));
      const first = Math.max(0, this.buffer.lowerBound(range[0]) - 1);
      const last = Math.min(this.buffer.count, this.buffer.lowerBound(range[1]) + 1);
      // Past the window the points stay in the buffer for the CSV export and zooming out.
      return this.buffer.columns(first, this.windowSeconds && !this.zoomRange ? this.buffer.count : last);
    }

    redraw() {
      const data = this.viewData();
      const range = this.visibleRange();
      const u = this.uplot;
      u.batch(() => {
        u.setData(data, range == null);
        if (range) u.setScale("x", {min: range[0], max: range[1]});
      });
      const times = data[0];
      this.counters.redraws++;
      this.counters.lastDrawnTime = times.length > 0 ? times[times.length - 1] : null;
      this.updateStatus();
    }

    // --- Reading out and exporting --------------------------------------------------------------

    // The values under the cursor: {index, time_s, values: [...]} or null off the plot.
    readout() {
      const u = this.uplot;
      const index = u.cursor.idx;
      if (index == null) return null;
      return {
        index: index,
        time_s: u.data[0][index],
        values: this.series.map((s, i) => u.data[i + 1][index]),
      };
    }

    // Every kept point (a trigger capture: the captured ones) as CSV: "time_s,NAME,...", one row
    // per sample, empty fields for gaps.
    exportCsv() {
      const data = this.frozen || this.buffer.columns(0, this.buffer.count);
      const lines = [["time_s"].concat(this.series.map((s) => s.name)).join(",")];
      for (let k = 0; k < data[0].length; k++) {
        const row = [String(data[0][k])];
        for (let i = 1; i < data.length; i++) row.push(data[i][k] == null ? "" : String(data[i][k]));
        lines.push(row.join(","));
      }
      return lines.join("\n") + "\n";
    }

    // The plot as a PNG data URL: the curves and axes as drawn, on white, with the title and one
    // legend line per curve (value under the cursor, or the last one) below. Its width is the plot
    // canvas's; its height the canvas's plus (1 + curves) lines of 18 CSS pixels (pngLineHeight()).
    exportPng() {
      const u = this.uplot;
      const plot = u.ctx.canvas;
      const line = this.pngLineHeight();
      const canvas = document.createElement("canvas");
      canvas.width = plot.width;
      canvas.height = plot.height + line * (1 + this.series.length);
      const ctx = canvas.getContext("2d");
      ctx.fillStyle = "#fff";
      ctx.fillRect(0, 0, canvas.width, canvas.height);
      ctx.drawImage(plot, 0, 0);
      const scale = line / kPngLineHeightCss;
      ctx.font = Math.round(13 * scale) + "px sans-serif";
      ctx.textBaseline = "middle";
      let y = plot.height + line / 2;
      const readout = this.readout();
      const data = u.data;
      const lastIndex = data[0].length - 1;
      const index = readout ? readout.index : lastIndex;
      const timeText = index >= 0 ? " at t = " + formatNumber(data[0][index]) + " s" : "";
      ctx.fillStyle = "#000";
      ctx.fillText((this.title ? this.title + ": " : "") + "values" + timeText, 8 * scale, y);
      this.series.forEach((s, i) => {
        y += line;
        ctx.fillStyle = s.color;
        ctx.fillRect(8 * scale, y - 5 * scale, 10 * scale, 10 * scale);
        ctx.fillStyle = "#000";
        const value = index >= 0 ? data[i + 1][index] : null;
        ctx.fillText(s.label + ": " + withUnit(formatNumber(value), s.unit), 24 * scale, y);
      });
      return canvas.toDataURL("image/png");
    }

    // Device pixels of one text line of exportPng.
    pngLineHeight() {
      return Math.round(kPngLineHeightCss * (global.devicePixelRatio || 1));
    }

    // For tests and status displays: pushes, redraws (at most one per animation frame), points
    // kept, the time of the last push and of the last point drawn.
    stats() {
      return {
        pushes: this.counters.pushes,
        redraws: this.counters.redraws,
        points: this.buffer.count,
        lastPushedTime_s: this.buffer.lastTime(),
        lastDrawnTime_s: this.counters.lastDrawnTime,
      };
    }

    destroy() {
      this.resizeObserver.disconnect();
      this.uplot.destroy();
      this.root.remove();
    }
  }

  global.MotwinScope = {
    create: (container, options) => new Scope(container, options),
    formatNumber: formatNumber,
  };
})(window);
