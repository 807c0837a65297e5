// The World view of the web console (docs/web-console.md, "The page"): the signals a scenario file
// sets for the chosen module (switch levels and positions, load torque, supply voltage, an
// obstacle ...) as controls, and each axis drawn live: a dial turning with the shaft and a track
// with the carriage between the switches. It talks through a WebSocket session of its own with
// the ops "world" and "world_set"; app.js starts it when the tab is shown and stops it on leaving.
(function () {
  "use strict";

  const RATE_HZ = 20;            // "world" polls a second while the view is shown
  const SLIDER_MAX_SPAN = 400;   // analog signals with a narrower range get a slider too
  const SVG = "http://www.w3.org/2000/svg";
  const SWITCHES = [["L", "left"], ["H", "home"], ["R", "right"]];

  const $ = (id) => document.getElementById(id);
  const view = {
    socket: null,
    module: 0,
    nextId: 1,
    waiting: new Map(),
    signals: [],        // the "world" reply's table
    values: {},         // name -> value (null: not set)
    axes: [],           // the reply's axes
    controls: new Map(),  // name -> {input, slider, note}
    ranges: [],         // per axis: the track's [low, high] in revolutions, only ever widened
    timer: null,
    polling: false,
    updates: 0,
    simTimeUs: 0,
  };

  function element(tag, className, text) {
    const node = document.createElement(tag);
    if (className) node.className = className;
    if (text !== undefined) node.textContent = text;
    return node;
  }

  function svg(tag, attributes, parent) {
    const node = document.createElementNS(SVG, tag);
    for (const [name, value] of Object.entries(attributes || {})) node.setAttribute(name, String(value));
    if (parent) parent.appendChild(node);
    return node;
  }

  function numberText(value) {
    if (value === null || value === undefined) return "";
    return String(Number(Number(value).toPrecision(7)));
  }

  // Range bounds: the position signals' ±1e6 short.
  function boundText(value) {
    return Math.abs(value) >= 1e5 ? value.toExponential(0).replace("e+", "e") : numberText(value);
  }

  function note(text) {
    $("world-note").textContent = text;
  }

  // --- Session ---------------------------------------------------------------------------------

  function send(message, callback) {
    const socket = view.socket;
    if (!socket || socket.readyState !== WebSocket.OPEN) return false;
    message.id = view.nextId++;
    if (callback) view.waiting.set(message.id, callback);
    socket.send(JSON.stringify(message));
    return true;
  }

  function start(module) {
    stop();
    view.module = module;
    view.values = {};
    view.ranges = [];
    view.updates = 0;
    $("world-axes").replaceChildren();
    $("world-controls").replaceChildren();
    $("world-none").hidden = true;
    note("connecting…");
    view.socket = window.motwinSession.open((socket) => view.socket === socket, {
      open: () => send({ op: "world", module: module }, onTable),
      message: (message) => {
        const callback = view.waiting.get(message.id);
        if (callback) {
          view.waiting.delete(message.id);
          callback(message);
        }
      },
      close: () => {
        stop();
        note("connection closed");
      },
    });
  }

  function stop() {
    if (view.timer) clearInterval(view.timer);
    view.timer = null;
    view.polling = false;
    view.waiting.clear();
    const socket = view.socket;
    view.socket = null;
    window.motwinSession.close(socket);
  }

  function onTable(reply) {
    if (!reply.ok) {
      $("world-none").hidden = false;
      $("world-none").textContent = reply.error || "no simulated world";
      note("");
      return;
    }
    view.signals = reply.signals;
    view.axes = reply.axes;
    for (const signal of reply.signals) view.values[signal.name] = signal.value;
    buildAxes(reply.axes);
    buildControls(reply);
    show(reply);
    view.timer = setInterval(poll, 1000 / RATE_HZ);
  }

  function poll() {
    if (view.polling) return;  // one at a time: a slow page gets fewer, not queued, updates
    view.polling = send({ op: "world", module: view.module, values_only: true }, (reply) => {
      view.polling = false;
      if (!reply.ok) return note("world: " + (reply.error || "refused"));
      Object.assign(view.values, reply.values);
      view.axes = reply.axes;
      show(reply);
    });
  }

  function show(reply) {
    view.updates++;
    view.simTimeUs = reply.sim_time_us;
    note("t = " + (reply.sim_time_us / 1e6).toFixed(3) + " s" +
      (reply.settable ? "" : " · read only: no scenario reaches a node of a --node bus"));
    for (const [name, control] of view.controls) showControl(name, control);
    view.axes.forEach(drawAxis);
  }

  // --- Controls --------------------------------------------------------------------------------

  function isLevel(signal) {
    return signal.whole && signal.min === 0 && signal.max === 1;
  }

  // The axis whose prefix a signal has ("AXIS1_" ...), or the module's own group.
  function groupOf(name) {
    const axis = view.axes.findIndex((a) => a.prefix !== "" && name.startsWith(a.prefix));
    return axis;
  }

  function buildControls(reply) {
    view.controls.clear();
    const container = $("world-controls");
    const groups = new Map();
    const groupElement = (axis) => {
      if (!groups.has(axis)) {
        const fieldset = element("fieldset", "world-group");
        fieldset.appendChild(element("legend", "", axis < 0 ? (view.axes.length > 1 ? "Module" : "Signals") : "Axis " + axis));
        const switches = element("div", "world-levels");
        const numbers = element("div", "world-numbers");
        fieldset.append(switches, numbers);
        container.appendChild(fieldset);
        groups.set(axis, { switches, numbers });
      }
      return groups.get(axis);
    };
    for (const signal of reply.signals) {
      const axis = groupOf(signal.name);
      const group = groupElement(axis);
      // In an axis's group its prefix goes without saying: "REF_L" for AXIS1_REF_L.
      const label = axis < 0 ? signal.name : signal.name.slice(view.axes[axis].prefix.length);
      const control = isLevel(signal) ? levelControl(signal, label, reply.settable)
        : numberControl(signal, label, reply.settable);
      control.row.title = signal.name + ": " + signal.description;
      (isLevel(signal) ? group.switches : group.numbers).appendChild(control.row);
      view.controls.set(signal.name, control);
    }
  }

  function levelControl(signal, label, settable) {
    const row = element("label", "world-level");
    const input = element("input");
    input.type = "checkbox";
    input.dataset.signal = signal.name;
    input.disabled = !settable;
    input.addEventListener("change", () => set(signal.name, input.checked ? 1 : 0));
    const noteElement = element("span", "world-reply");
    row.append(input, element("span", "world-name", label), noteElement);
    return { row, input, note: noteElement, signal };
  }

  function numberControl(signal, labelText, settable) {
    const row = element("div", "world-number");
    const label = element("label", "world-name", labelText);
    const input = element("input");
    input.type = "number";
    input.dataset.signal = signal.name;
    input.min = signal.min;
    input.max = signal.max;
    input.step = signal.whole ? "1" : "any";
    input.placeholder = "not set";
    input.disabled = !settable;
    input.id = "world-" + signal.name;
    label.htmlFor = input.id;
    const commit = () => {
      if (input.value === "") return showControl(signal.name, view.controls.get(signal.name));
      set(signal.name, Number(input.value));
    };
    input.addEventListener("change", commit);
    input.addEventListener("keydown", (event) => {
      if (event.key === "Escape") {
        input.blur();
        showControl(signal.name, view.controls.get(signal.name));
      }
    });
    row.append(label, input, element("span", "world-unit", signal.unit || ""));
    let slider = null;
    if (!signal.whole && signal.max - signal.min <= SLIDER_MAX_SPAN) {
      slider = element("input", "world-slider");
      slider.type = "range";
      slider.min = signal.min;
      slider.max = signal.max;
      slider.step = (signal.max - signal.min) / 2000;
      slider.disabled = !settable;
      slider.setAttribute("aria-label", signal.name);
      slider.addEventListener("input", () => { input.value = numberText(Number(slider.value)); });
      slider.addEventListener("change", () => set(signal.name, Number(slider.value)));
    }
    row.appendChild(slider || element("span"));
    row.appendChild(element("span", "world-range info", boundText(signal.min) + " … " + boundText(signal.max)));
    const noteElement = element("span", "world-reply");
    row.appendChild(noteElement);
    return { row, input, slider, note: noteElement, signal };
  }

  // The control shows the world's value, unless the user is at it.
  function showControl(name, control) {
    const value = view.values[name];
    if (control.input.type === "checkbox") {
      control.input.checked = value === 1;
      return;
    }
    if (document.activeElement !== control.input) control.input.value = numberText(value);
    if (control.slider && document.activeElement !== control.slider && value !== null && value !== undefined) {
      control.slider.value = value;
    }
  }

  function set(name, value) {
    const control = view.controls.get(name);
    control.note.textContent = "…";
    control.note.classList.remove("error");
    const sent = send({ op: "world_set", module: view.module, signal: name, value: value }, (reply) => {
      control.note.textContent = reply.ok ? "set at " + (reply.sim_time_us / 1e6).toFixed(3) + " s" : reply.error;
      control.note.classList.toggle("error", !reply.ok);
      if (reply.ok) view.values[name] = reply.value;
      // Refused: the control shows the world's value again, which did not change.
      if (!reply.ok && control.input.type !== "checkbox") control.input.value = numberText(view.values[name]);
      showControl(name, control);
    });
    if (!sent) control.note.textContent = "not connected";
  }

  // --- Drawing ---------------------------------------------------------------------------------

  function buildAxes(axes) {
    const container = $("world-axes");
    axes.forEach((axis, index) => {
      const figure = element("figure", "world-axis");
      figure.id = "world-axis-" + index;
      const drawing = svg("svg", { viewBox: "0 0 400 150", role: "img", class: "world-drawing" }, figure);
      svg("title", {}, drawing).textContent = (axes.length > 1 ? "Axis " + index : "Axis") + ": shaft and switches";
      figure.appendChild(element("figcaption", "world-caption"));
      container.appendChild(figure);
    });
  }

  function value(name) {
    const v = view.values[name];
    return typeof v === "number" && Number.isFinite(v) ? v : null;
  }

  // Where each switch of an axis is: a limit beyond a position (AT) or a window (FROM..TO), as the
  // board's table has them; `level` is what the module senses.
  function switchesOf(prefix) {
    return SWITCHES.map(([letter, name]) => {
      const at = value(prefix + "REF_" + letter + "_AT");
      const from = value(prefix + "REF_" + letter + "_FROM");
      const to = value(prefix + "REF_" + letter + "_TO");
      let low = null;
      let high = null;
      if (at !== null) {
        if (letter === "L") high = at; else low = at;  // left: at and below; right, home: at and above
      } else if (from !== null || to !== null) {
        low = from;
        high = to;
      }
      return { letter, name, low, high, level: value(prefix + "REF_" + letter) };
    });
  }

  function trackRange(index, position, switches) {
    const points = [];
    if (position !== null) points.push(position);
    for (const s of switches) {
      if (s.low !== null) points.push(s.low);
      if (s.high !== null) points.push(s.high);
    }
    let low = points.length ? Math.min(...points) : 0;
    let high = points.length ? Math.max(...points) : 1;
    if (high - low < 1) {
      const middle = (low + high) / 2;
      low = middle - 0.5;
      high = middle + 0.5;
    }
    const pad = (high - low) * 0.15;
    low -= pad;
    high += pad;
    const kept = view.ranges[index];
    // Widen only, so that the scale does not jump with every sample; narrow again when the
    // carriage is far inside a much larger range (a long move came back).
    if (kept && kept[0] <= low && kept[1] >= high && (high - low) * 8 > kept[1] - kept[0]) return kept;
    const range = kept && (high - low) * 8 > kept[1] - kept[0]
      ? [Math.min(kept[0], low), Math.max(kept[1], high)] : [low, high];
    view.ranges[index] = range;
    return range;
  }

  function drawAxis(axis, index) {
    const figure = $("world-axis-" + index);
    if (!figure) return;
    const drawing = figure.querySelector("svg");
    const title = drawing.querySelector("title");
    drawing.replaceChildren(title);
    const prefix = axis.prefix;
    const position = typeof axis.position_rev === "number" ? axis.position_rev : null;
    const switches = switchesOf(prefix);
    const blocked = value(prefix + "BLOCKED") === 1;

    // The dial: one turn is 360°, 0 at the top, forward clockwise.
    const cx = 70;
    const cy = 75;
    const r = 55;
    svg("circle", { cx, cy, r, class: "world-dial" + (blocked ? " blocked" : "") }, drawing);
    for (let k = 0; k < 12; k++) {
      const a = k * Math.PI / 6;
      const inner = k % 3 === 0 ? r - 10 : r - 5;
      svg("line", { x1: cx + inner * Math.sin(a), y1: cy - inner * Math.cos(a), x2: cx + r * Math.sin(a),
        y2: cy - r * Math.cos(a), class: "world-tick" }, drawing);
    }
    if (position !== null) {
      const angle = ((position % 1) + 1) % 1 * 360;
      drawing.dataset.positionRev = String(position);
      drawing.dataset.angleDeg = angle.toFixed(3);
      svg("line", { x1: cx, y1: cy, x2: cx, y2: cy - r + 8, transform: `rotate(${angle.toFixed(3)} ${cx} ${cy})`,
        class: "world-pointer", "data-angle-deg": angle.toFixed(3) }, drawing);
      svg("circle", { cx, cy, r: 4, class: "world-hub" }, drawing);
    } else {
      delete drawing.dataset.positionRev;
      delete drawing.dataset.angleDeg;
      const text = svg("text", { x: cx, y: cy + 4, class: "world-label", "text-anchor": "middle" }, drawing);
      text.textContent = "no rotor";
    }
    if (blocked) {
      const text = svg("text", { x: cx, y: cy + r - 14, class: "world-blocked-label", "text-anchor": "middle" }, drawing);
      text.textContent = "BLOCKED";
    }

    // The track: the carriage at the shaft's position between the switches (revolutions).
    const x0 = 150;
    const x1 = 390;
    const y = 70;
    const [low, high] = trackRange(index, position, switches);
    const x = (rev) => x0 + (Math.min(Math.max(rev, low), high) - low) / (high - low) * (x1 - x0);
    svg("line", { x1: x0, y1: y, x2: x1, y2: y, class: "world-rail" }, drawing);
    const rows = { L: 0, H: 1, R: 0 };
    for (const s of switches) {
      if (s.low === null && s.high === null) continue;
      const from = x(s.low === null ? low : s.low);
      const to = x(s.high === null ? high : s.high);
      const band = svg("rect", { x: from, y: y - 30 - rows[s.letter] * 10, width: Math.max(to - from, 1), height: 8,
        class: "world-switch" + (s.level === 1 ? " active" : "") }, drawing);
      band.dataset.switch = s.letter;
      const edge = s.letter === "L" ? to : from;
      svg("line", { x1: edge, y1: y - 34 - rows[s.letter] * 10, x2: edge, y2: y + 6, class: "world-switch-edge" }, drawing);
      const label = svg("text", { x: edge + (s.letter === "L" ? -3 : 3), y: y - 34 - rows[s.letter] * 10,
        "text-anchor": s.letter === "L" ? "end" : "start", class: "world-label" }, drawing);
      label.textContent = s.letter + " " + numberText(s.letter === "L" ? s.high : s.low);
    }
    if (position !== null) {
      const cxCarriage = x(position);
      if (blocked) svg("rect", { x: cxCarriage - 12, y: y - 16, width: 24, height: 32, class: "world-obstacle" }, drawing);
      svg("rect", { x: cxCarriage - 7, y: y - 10, width: 14, height: 20, rx: 2, class: "world-carriage" }, drawing);
    }
    for (const [k, tick] of [[0, low], [1, high]]) {
      const text = svg("text", { x: k ? x1 : x0, y: y + 22, "text-anchor": k ? "end" : "start", class: "world-label" }, drawing);
      text.textContent = numberText(tick.toFixed(2)) + " rev";
    }
    // The levels the module senses, as chips under the track.
    switches.forEach((s, k) => {
      if (s.level === null) return;
      const chip = svg("text", { x: x0 + k * 80, y: y + 50, class: "world-level-chip" + (s.level === 1 ? " active" : "") },
        drawing);
      chip.textContent = s.name + " " + (s.level === 1 ? "1" : "0");
    });

    const caption = figure.querySelector("figcaption");
    const parts = [];
    parts.push(view.axes.length > 1 ? "Axis " + index : "Shaft");
    parts.push(position === null ? "ideal motor: no rotor to draw (serve --motor PRESET)" : numberText(position.toFixed(4)) + " rev");
    if (typeof axis.speed_rpm === "number") parts.push(numberText(axis.speed_rpm.toFixed(1)) + " rpm");
    if (typeof axis.torque_nm === "number") parts.push(numberText(axis.torque_nm.toFixed(4)) + " N m");
    if (blocked) parts.push("blocked");
    caption.textContent = parts.join(" · ");
  }

  // For scripts and tests: the session's state.
  window.MotwinWorld = {
    start,
    stop,
    get running() { return view.socket !== null; },
    get updates() { return view.updates; },
    get values() { return Object.assign({}, view.values); },
    get axes() { return view.axes.slice(); },
  };
})();
