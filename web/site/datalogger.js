// The Scope view's datalogger mode: a capture of the module's datalogger (TMCL command 142,
// docs/datalogger.md) at its base rate, plotted against simulated time at the samples' real
// spacing on the scope component (scope.js). Everything goes through the "datalogger" op of the
// console's protocol (docs/web-console.md), which sends the module's own 142 requests: the page
// can do nothing a TMCL host could not. Offered only where the module answers GET_INFO (the
// TMCM-1636); the TMCM-142 answers status 2, a CANopen node takes no TMCL.
//
// app.js calls MotwinDatalogger.moduleChosen() and .viewShown(name); it gives the module and its
// rows through window.motwinConsole. For scripts and tests: window.motwinDatalogger.
(function (global) {
  "use strict";

  const kRateDividers = [1, 2, 4, 10, 20, 40, 100, 200];  // prescaler + 1
  const kDefaultSamples = 1000;
  const kPollMs = 100;  // GET_STATE while a capture runs (wall time)
  const kDataloggerBanks = [0, 2];  // the global parameter banks a channel may sample

  const $ = (id) => document.getElementById(id);
  const state = {
    module: null,        // the module the datalogger mode is for
    info: null,          // {channels, buffer_words, base_rate_hz} as the module answered GET_INFO
    infoAnswered: false, // the module answered GET_INFO (with its figures or a refusal)
    mode: "live",        // "live" | "datalogger"
    socket: null,        // the mode's own WebSocket session
    nextId: 1,
    waiting: new Map(),
    queue: [],           // requests not sent yet
    inFlight: false,     // a request waits for its reply
    running: false,      // a capture is set up, armed, being read or about to repeat
    run: null,           // {channels (rows), prescaler, samples, trigger, repeat}
    pollTimer: null,
    scope: null,         // the MotwinScope of the last capture
    captures: 0,
    last: null,          // the last read reply
    view: "parameters",
  };

  global.motwinDatalogger = {
    get available() { return state.info !== null; },
    get infoAnswered() { return state.infoAnswered; },
    get info() { return state.info; },
    get mode() { return state.mode; },
    get running() { return state.running; },
    get sessionOpen() { return state.socket !== null; },
    get scope() { return state.scope; },
    get captures() { return state.captures; },
    get last() { return state.last; },
  };

  function console_() {
    return global.motwinConsole || {};
  }

  // --- The mode's session -------------------------------------------------------------------------

  // The mode's requests go one at a time, each after the previous one's reply: a Stop's INIT
  // then never lands between the instructions of a start still being sent.
  function openSession() {
    if (state.socket) return;
    state.socket = global.motwinSession.open((socket) => state.socket === socket, {
      open: () => pump(),
      message: (message) => {
        const callback = state.waiting.get(message.id);
        if (callback) {
          state.waiting.delete(message.id);
          state.inFlight = false;
          callback(message);
          pump();
        }
      },
      close: () => {
        state.socket = null;
        state.waiting.clear();
        state.queue = [];
        state.inFlight = false;
        if (state.running) stopCapture("connection closed", false);
      },
    });
  }

  function closeSession() {
    const socket = state.socket;
    state.socket = null;
    state.waiting.clear();
    state.queue = [];
    state.inFlight = false;
    global.motwinSession.close(socket);
  }

  function ask(message, callback) {
    openSession();
    message.id = state.nextId++;
    message.op = "datalogger";
    message.module = state.module.module;
    state.queue.push({ message: message, callback: callback });
    pump();
  }

  function pump() {
    const socket = state.socket;
    if (state.inFlight || state.queue.length === 0 || !socket || socket.readyState !== WebSocket.OPEN) return;
    const next = state.queue.shift();
    state.inFlight = true;
    state.waiting.set(next.message.id, next.callback);
    socket.send(JSON.stringify(next.message));
  }

  function replyText(reply) {
    if (reply.error) return reply.error;
    if (reply.status !== undefined) return (reply.step ? reply.step + ": " : "") + "status " + reply.status + " " + (reply.status_name || "");
    return "failed";
  }

  // --- Module and view ----------------------------------------------------------------------------

  // A module was chosen (or the list read again): ask it for its datalogger's figures.
  function moduleChosen() {
    stopCapture("module changed", false);
    closeSession();
    const chosen = console_().module || null;
    if (state.scope && (!chosen || !state.module || chosen.module !== state.module.module)) {
      state.scope.destroy();  // its curves were the other module's
      state.scope = null;
    }
    state.info = null;
    state.infoAnswered = false;
    state.module = chosen;
    setMode("live");
    $("scope-mode").hidden = true;
    if (!state.module || state.module.protocol !== "tmcl") return;
    const module = state.module;
    ask({ action: "info" }, (reply) => {
      if (state.module !== module) return;
      state.infoAnswered = true;
      if (!reply.ok) {
        closeSession();  // no datalogger (the TMCM-142 answers status 2): live mode only
        return;
      }
      state.info = reply;
      $("scope-mode").hidden = false;
      $("datalogger-mode-label").textContent = "Datalogger (" + reply.base_rate_hz + " Hz, " + reply.channels + " channels)";
      renderSetup();
      if (!state.running) closeSession();  // opened again by Capture: a session only while one runs
    });
  }

  function viewShown(name) {
    state.view = name;
    if (name !== "scope") stopCapture("left the Scope view", false);
  }

  function setMode(mode) {
    state.mode = mode === "datalogger" && state.info ? "datalogger" : "live";
    const datalogger = state.mode === "datalogger";
    for (const radio of document.querySelectorAll("input[name=scope-mode]")) radio.checked = radio.value === state.mode;
    if (datalogger) {
      const liveStop = $("scope-stop");
      if (liveStop && !liveStop.disabled) liveStop.click();  // one mode at a time
    } else {
      stopCapture("live mode", true);
    }
    document.querySelector("#view-scope .scope-setup").hidden = datalogger;
    $("scope-plot").hidden = datalogger;
    $("datalogger").hidden = !datalogger;
  }

  // --- Setup --------------------------------------------------------------------------------------

  // The rows a channel can sample: readable axis parameters of each motor and global parameters
  // of banks 0 and 2 (SET_CHANNEL's types 1 and 8; docs/datalogger.md "Channels").
  function channelRows() {
    const rows = console_().rows || [];
    return rows.filter((row) => row.readable && row.address && row.address.kind &&
      (row.address.kind === "axis" || kDataloggerBanks.includes(row.address.bank)));
  }

  // A channel's choices: on a module of more than one motor, grouped by motor (then the global
  // parameters), so that a channel picks its motor with its parameter.
  function addChannelOptions(select, rows) {
    const motors = new Set(rows.filter((row) => row.motor !== undefined).map((row) => row.motor));
    const groups = new Map();
    for (const row of rows) {
      const option = new Option(row.title + " " + row.name + (row.unit ? " (" + row.unit + ")" : ""), row.key);
      if (motors.size < 2) {
        select.add(option);
        continue;
      }
      const group = row.motor !== undefined ? "Motor " + row.motor : "Global parameters";
      if (!groups.has(group)) {
        const element = document.createElement("optgroup");
        element.label = group;
        select.appendChild(element);
        groups.set(group, element);
      }
      groups.get(group).appendChild(option);
    }
  }

  function renderSetup() {
    const info = state.info;
    const rows = channelRows();
    const channels = $("datalogger-channels");
    channels.replaceChildren();
    const defaults = ["a52", "a42"];  // actual position and velocity, where the module has them
    for (let c = 0; c < info.channels; c++) {
      const select = document.createElement("select");
      select.className = "datalogger-channel";
      select.setAttribute("aria-label", "Channel " + (c + 1));
      select.add(new Option("–", ""));
      addChannelOptions(select, rows);
      if (defaults[c] && rows.some((row) => row.key === defaults[c])) select.value = defaults[c];
      select.addEventListener("change", updateSetup);
      const label = document.createElement("label");
      label.append("Ch " + (c + 1) + " ", select);
      channels.appendChild(label);
    }
    const rate = $("datalogger-rate");
    rate.replaceChildren();
    for (const divider of kRateDividers) {
      rate.add(new Option(formatHz(info.base_rate_hz / divider) + " (every " + formatSeconds(divider / info.base_rate_hz) + ")",
        String(divider - 1)));
    }
    $("datalogger-samples").value = String(kDefaultSamples);
    updateSetup();
  }

  function formatHz(hz) {
    return (Number.isInteger(hz) ? hz : hz.toFixed(1)) + " Hz";
  }

  function formatSeconds(s) {
    return s < 1e-3 ? (s * 1e6).toFixed(0) + " µs" : s < 1 ? Number((s * 1e3).toPrecision(4)) + " ms" : s + " s";
  }

  function pickedRows() {
    const rows = channelRows();
    const picked = [];
    for (const select of document.querySelectorAll("#datalogger-channels select")) {
      const row = rows.find((r) => r.key === select.value);
      if (row) picked.push(row);
    }
    return picked;
  }

  // Limits follow the choice: samples per channel at most the buffer over the channels; the
  // trigger channel one of the picked ones.
  function updateSetup() {
    const picked = pickedRows();
    const maxSamples = Math.floor(state.info.buffer_words / Math.max(1, picked.length));
    const samples = $("datalogger-samples");
    samples.max = String(maxSamples);
    const trigger = $("datalogger-trigger");
    const chosen = trigger.value;
    trigger.replaceChildren(new Option("none (at once)", ""));
    picked.forEach((row, i) => trigger.add(new Option(row.title + " " + row.name, String(i))));
    if (Number(chosen) < picked.length) trigger.value = chosen;
    showNote();
  }

  function showNote(text) {
    const picked = pickedRows();
    if (text === undefined) {
      const samples = Number($("datalogger-samples").value) || 0;
      const period = (Number($("datalogger-rate").value) + 1) / state.info.base_rate_hz;
      text = state.running ? "capturing…"
        : picked.length + " channel" + (picked.length === 1 ? "" : "s") + ", " + samples + " samples each: " +
          formatSeconds(samples * period) + " (at most " + $("datalogger-samples").max + " samples)";
    }
    $("datalogger-note").textContent = text;
    $("datalogger-start").disabled = state.running || picked.length === 0;
    $("datalogger-stop").disabled = !state.running;
    for (const element of document.querySelectorAll("#datalogger .datalogger-setup select, #datalogger .datalogger-setup input")) {
      element.disabled = state.running;
    }
  }

  // --- Capture ------------------------------------------------------------------------------------

  function startCapture() {
    if (state.running || !state.info) return;
    const rows = pickedRows();
    if (rows.length === 0) return;
    const maxSamples = Math.floor(state.info.buffer_words / rows.length);
    const samples = Math.max(1, Math.min(maxSamples, Math.floor(Number($("datalogger-samples").value) || kDefaultSamples)));
    $("datalogger-samples").value = String(samples);
    const run = {
      rows: rows,
      prescaler: Number($("datalogger-rate").value),
      samples: samples,
      trigger: null,
      repeat: $("datalogger-repeat").value === "repeat",
    };
    if ($("datalogger-trigger").value !== "") {
      const pretrigger = Math.max(0, Math.min(samples, Math.floor(Number($("datalogger-pretrigger").value) || 0)));
      $("datalogger-pretrigger").value = String(pretrigger);
      run.trigger = {
        channel: Number($("datalogger-trigger").value),
        level: Math.round(Number($("datalogger-level").value) || 0),
        edge: $("datalogger-edge").value,
        pretrigger: pretrigger,
      };
    }
    state.run = run;
    state.running = true;
    showNote();
    arm();
  }

  // One capture: set up and enabled, then its state polled until complete, then read.
  function arm() {
    const run = state.run;
    const request = {
      action: "start",
      channels: run.rows.map((row) => row.address.kind === "axis"
        ? { kind: "axis", number: row.address.number, axis: row.address.axis }
        : { kind: "global", number: row.address.number, bank: row.address.bank }),
      samples: run.samples,
      prescaler: run.prescaler,
    };
    if (run.trigger) request.trigger = run.trigger;
    ask(request, (reply) => {
      if (!state.running || state.run !== run) return;
      if (!reply.ok) return stopCapture("refused: " + replyText(reply), false);
      showNote(run.trigger ? "armed: waiting for the trigger" : "capturing…");
      poll(run);
    });
  }

  function poll(run) {
    state.pollTimer = setTimeout(() => {
      state.pollTimer = null;
      if (!state.running || state.run !== run) return;
      ask({ action: "state" }, (reply) => {
        if (!state.running || state.run !== run) return;
        if (!reply.ok) return stopCapture("state: " + replyText(reply), false);
        if (reply.state !== "complete") {
          const words = run.samples * run.rows.length;
          showNote((reply.state === "trigger" || reply.state === "pretrigger" ? "armed (" + reply.state + ")" : reply.state) +
            ": " + Math.min(100, Math.round(100 * reply.captured_words / words)) + " % captured");
          if (reply.state === "idle") return stopCapture("the datalogger was reset (INIT from another host?)", false);
          return poll(run);
        }
        showNote("reading " + run.samples * run.rows.length + " samples…");
        ask({ action: "read" }, (read) => {
          if (!state.running || state.run !== run) return;
          if (!read.ok) return stopCapture("read: " + replyText(read), false);
          plot(run, read);
          if (run.repeat) return arm();
          state.running = false;
          state.run = null;
          closeSession();
          showNote("captured " + read.samples + " samples per channel at t = " + (read.sim_time_us / 1e6).toFixed(3) + " s");
        });
      });
    }, kPollMs);
  }

  // The samples against simulated time at their spacing: 0 is the first sample at or after the
  // trigger (the first sample without one).
  function plot(run, read) {
    const period_s = (run.prescaler + 1) / read.base_rate_hz;
    const times = new Array(read.samples);
    for (let k = 0; k < read.samples; k++) times[k] = Number(((k - read.pretrigger_samples) * period_s).toFixed(9));
    const title = state.module.name + ": datalogger, " + formatHz(read.base_rate_hz / (run.prescaler + 1)) +
      (run.trigger ? ", trigger at 0 s" : "");
    const series = run.rows.map((row) => ({ name: row.curveName, label: row.title + " " + row.name, unit: row.unit }));
    const same = state.scope && state.scope.title === title && state.scope.series.length === series.length &&
      state.scope.series.every((s, i) => s.name === series[i].name);
    if (!same) {
      if (state.scope) state.scope.destroy();
      const container = $("datalogger-plot");
      state.scope = MotwinScope.create(container, {
        series: series,
        windowSeconds: null,
        title: title,
        capacity: Math.max(read.samples, 1),
        height: Math.max(180, Math.min(480, Math.floor(global.innerHeight - container.getBoundingClientRect().top - 150))),
      });
    }
    state.scope.setData(times, read.values);
    state.last = read;
    state.captures++;
  }

  // The capture ends here: with `sendInit` (Stop, live mode) INIT stops it in the module too;
  // otherwise (another tab, another module, the session gone) the module keeps what it was doing,
  // as with a host that goes away. The mode's session closes (after the INIT's reply).
  function stopCapture(why, sendInit) {
    if (state.pollTimer) clearTimeout(state.pollTimer);
    state.pollTimer = null;
    const wasRunning = state.running;
    state.running = false;
    state.run = null;
    if (wasRunning && sendInit && state.socket) ask({ action: "stop" }, () => { if (!state.running) closeSession(); });
    else if (!state.running) closeSession();
    if (wasRunning && state.info && $("datalogger-note")) showNote(why);
  }

  // The mode switch and the datalogger's controls, in the containers index.html gives.
  function build() {
    $("scope-mode").innerHTML =
      '<span class="info">Sampling</span>' +
      '<label><input type="radio" name="scope-mode" value="live" checked> Live (subscription, up to 100 /s)</label>' +
      '<label><input type="radio" name="scope-mode" value="datalogger"> <span id="datalogger-mode-label">Datalogger</span></label>';
    $("datalogger").innerHTML =
      '<div class="datalogger-setup">' +
      '  <div id="datalogger-channels" class="datalogger-channels" aria-label="Channels the datalogger samples"></div>' +
      '  <div class="toolbar">' +
      '    <label>Rate <select id="datalogger-rate" aria-label="Sample rate"></select></label>' +
      '    <label>Samples <input id="datalogger-samples" type="number" min="1" step="1" aria-label="Samples per channel"></label>' +
      '    <label>Trigger <select id="datalogger-trigger" aria-label="Trigger channel"></select></label>' +
      '    <label>Edge <select id="datalogger-edge" aria-label="Trigger edge">' +
      '      <option value="rising">rising</option><option value="falling">falling</option><option value="both">both</option></select></label>' +
      '    <label>Level <input id="datalogger-level" type="number" step="1" value="0" aria-label="Trigger level"></label>' +
      '    <label>Pretrigger <input id="datalogger-pretrigger" type="number" min="0" step="1" value="0" aria-label="Samples before the trigger"></label>' +
      '    <select id="datalogger-repeat" aria-label="Single shot or repeat">' +
      '      <option value="single">single shot</option><option value="repeat">repeat</option></select>' +
      '  </div>' +
      '</div>' +
      '<div class="toolbar">' +
      '  <button id="datalogger-start" type="button">Capture</button>' +
      '  <button id="datalogger-stop" type="button" disabled>Stop</button>' +
      '  <span id="datalogger-note" class="info" role="status"></span>' +
      '</div>' +
      '<div id="datalogger-plot"></div>';
  }

  function start() {
    build();
    for (const radio of document.querySelectorAll("input[name=scope-mode]")) {
      radio.addEventListener("change", () => { if (radio.checked) setMode(radio.value); });
    }
    $("datalogger-start").addEventListener("click", startCapture);
    $("datalogger-stop").addEventListener("click", () => stopCapture("stopped", true));
    $("datalogger-samples").addEventListener("input", () => showNote());
    $("datalogger-rate").addEventListener("change", () => showNote());
  }

  global.MotwinDatalogger = { moduleChosen: moduleChosen, viewShown: viewShown };
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start);
  else start();
})(window);
