// The Motwin web console: a client of serve's JSON protocol (docs/web-console.md), like any
// script. Plain JavaScript, no build step; the server's Content-Security-Policy allows no inline
// script, so everything lives here.
(function () {
  "use strict";

  const LIVE_RATE_HZ = 20;
  const MAX_LIVE_ROWS = 64;  // the server's limit of subscribed items
  // A CANopen node's values are SDO uploads on the bus: fewer, less often, so that the page's
  // reading does not load the bus a master shares (16 objects at 10 Hz: about 4 % of 1 Mbit/s).
  const CANOPEN_LIVE_RATE_HZ = 10;
  const CANOPEN_MAX_LIVE_ROWS = 16;
  const HISTORY_LENGTH = 100;
  // The Scope view: curves of its own session (a second WebSocket), so that its subscription and
  // the Parameters view's never replace each other. Rates in updates a second.
  const SCOPE_MAX_CURVES = 8;
  const SCOPE_RATES_HZ = [10, 20, 25, 50, 100];
  const SCOPE_DEFAULT_RATE_HZ = 25;
  const CANOPEN_SCOPE_RATES_HZ = [5, 10, 20];
  const CANOPEN_SCOPE_DEFAULT_RATE_HZ = 10;

  const $ = (id) => document.getElementById(id);
  const state = {
    socket: null,
    nextId: 1,
    waiting: new Map(),   // request id -> callback
    modules: [],
    module: 0,
    motor: 0,             // the Parameters view's motor (a module of more than one)
    rows: [],             // rows of the chosen module, the axis parameters once per motor
    shown: [],            // rows that pass the filter
    liveKeys: new Set(),  // keys of the rows whose values are subscribed
    view: "parameters",
    history: [],
    historyIndex: 0,
    scope: {
      picked: [],         // keys of the rows picked as curves, in the order picked
      motor: 0,           // the motor whose axis parameters the picker lists
      socket: null,       // the scope's own session while it runs
      instance: null,     // the MotwinScope of the last run (kept after Stop for zoom and export)
      running: false,
      updates: 0,
    },
  };
  // For scripts and tests: the scope of the last run and whether it runs.
  window.motwinConsole = {
    get scope() { return state.scope.instance; },
    get scopeRunning() { return state.scope.running; },
    get module() { return currentModule(); },  // for the datalogger mode (datalogger.js)
    get rows() { return state.rows; },
    get motor() { return state.motor; },
  };

  // --- Connection --------------------------------------------------------------------------------

  const socketUrl = window.motwinSession.socketUrl;

  function setConnection(text, name) {
    $("connection").textContent = text;
    document.body.dataset.state = name;
  }

  function connect() {
    setConnection("connecting…", "connecting");
    const socket = new WebSocket(socketUrl(), "motwin");
    state.socket = socket;
    socket.addEventListener("open", () => {
      setConnection("connected", "connected");
      request({ op: "list" }, onList);
    });
    socket.addEventListener("message", (event) => onMessage(event.data));
    socket.addEventListener("close", () => {
      state.waiting.clear();
      setConnection("disconnected: retrying", "disconnected");
      setTimeout(connect, 2000);
    });
  }

  // The Scope's and the CANopen view's sessions (session.js).
  const openSession = window.motwinSession.open;
  const closeSession = window.motwinSession.close;

  function request(message, callback) {
    const id = state.nextId++;
    message.id = id;
    if (callback) state.waiting.set(id, callback);
    if (state.socket && state.socket.readyState === WebSocket.OPEN) state.socket.send(JSON.stringify(message));
    return id;
  }

  function onMessage(text) {
    let message;
    try {
      message = JSON.parse(text);
    } catch (error) {
      return;
    }
    if (message.push === "update") return onUpdate(message);
    if (message.push === "event") return logLine("event", "command " + message.command + " reply, value " + message.value);
    const callback = state.waiting.get(message.id);
    if (callback) {
      state.waiting.delete(message.id);
      callback(message);
    }
  }

  // --- Modules -----------------------------------------------------------------------------------

  function onList(reply) {
    if (!reply.ok) return;
    state.modules = reply.modules;
    const picker = $("module-picker");
    picker.replaceChildren();
    for (const module of reply.modules) {
      const option = document.createElement("option");
      option.value = module.module;
      option.textContent = module.name + (module.node_id !== undefined ? " (node " + module.node_id + ")" : "");
      picker.appendChild(option);
    }
    state.module = Math.min(state.module, reply.modules.length - 1);
    picker.value = String(state.module);
    chooseModule(state.module);
  }

  function currentModule() {
    return state.modules[state.module];
  }

  function isCanopen() {
    const module = currentModule();
    return module && module.protocol === "canopen";
  }

  function chooseModule(index) {
    stopScope(index !== state.module ? "module changed" : "module list read again");
    if (state.scope.instance && index !== state.module) {  // its curves were the other module's
      state.scope.instance.destroy();
      state.scope.instance = null;
    }
    const sameModule = index === state.module;
    state.module = index;
    const module = currentModule();
    if (!module) return;
    $("module-info").textContent = module.product + " · firmware " + module.firmware +
      (module.protocol === "none" ? " · not reachable from the console" : "");
    $("canopen-controls").hidden = !isCanopen();
    state.motor = sameModule ? Math.min(state.motor, motorCount(module) - 1) : 0;
    state.scope.motor = sameModule ? Math.min(state.scope.motor, motorCount(module) - 1) : 0;
    fillMotorPicker($("motor-picker"), $("motor-pick"), module, state.motor);
    fillMotorPicker($("scope-motor"), $("scope-motor-pick"), module, state.scope.motor);
    state.rows = rowsOf(module);
    applyFilter();
    resetScopeChoices();
    if (window.MotwinDatalogger) window.MotwinDatalogger.moduleChosen();
    if (state.view === "canopen") startCanopenView();
    if (state.view === "world") window.MotwinWorld.start(state.module);
    announceView();
  }

  // The motors whose axis parameters the page addresses (TMCL motor 0..n-1; `motors` of `list`).
  // A CANopen node's axes are objects of their own: no motor to choose.
  function motorCount(module) {
    if (!module || !module.sections.some((section) => section.kind === "axis")) return 1;
    return Math.max(1, module.motors || 1);
  }

  // A motor selector, shown only for a module of more than one motor.
  function fillMotorPicker(select, wrapper, module, motor) {
    const count = motorCount(module);
    select.replaceChildren();
    for (let m = 0; m < count; m++) select.add(new Option(String(m), String(m), false, m === motor));
    wrapper.hidden = count < 2;
  }

  // The key of a row (and of an update's entry, which echoes the row's address): motor 0's axis
  // parameter n is "a" + n, as on a module of one motor; motor m's "a" + n + "@" + m.
  function keyOf(address) {
    if (address.index !== undefined) {
      return "o" + address.index.toString(16).toUpperCase().padStart(4, "0") + "." + (address.sub || 0);
    }
    if (address.kind === "global") return "g" + address.bank + "." + address.number;
    return "a" + address.number + (address.axis ? "@" + address.axis : "");
  }

  // One table row per parameter or object entry (an axis parameter once per motor), with the
  // fields a request needs. `title` and `curveName` name the row outside the Parameters view's
  // table (the Scope's curves, the datalogger's channels): with the motor, where there are more.
  function rowsOf(module) {
    const rows = [];
    const motors = motorCount(module);
    for (const section of module.sections) {
      if (section.kind === "objects") {
        for (const object of section.objects) {
          const hex = object.index.toString(16).toUpperCase().padStart(4, "0");
          rows.push({
            key: "o" + hex + "." + object.sub,
            label: hex + "." + object.sub,
            title: hex + "." + object.sub,
            curveName: hex + "." + object.sub,
            section: section.title,
            name: object.name,
            unit: object.type,
            range: object.min !== undefined ? object.min + " … " + object.max : "",
            access: object.access,
            defaultValue: object.default,
            writable: object.access === "rw" || object.access === "wo",
            readable: object.access !== "wo",
            address: { module: module.module, index: object.index, sub: object.sub },
          });
        }
        continue;
      }
      const prefix = section.kind === "axis" ? "AP " : "GP " + section.bank + ".";
      if (section.kind !== "axis") {
        for (const parameter of section.parameters) rows.push(parameterRow(module, section, parameter, prefix, undefined, motors));
        continue;
      }
      for (let motor = 0; motor < motors; motor++) {
        for (const parameter of section.parameters) rows.push(parameterRow(module, section, parameter, prefix, motor, motors));
      }
    }
    return rows;
  }

  // An axis parameter of `motor`, or a global parameter (`motor` undefined).
  function parameterRow(module, section, parameter, prefix, motor, motors) {
    const address = motor !== undefined
      ? { module: module.module, kind: "axis", number: parameter.number, axis: motor }
      : { module: module.module, kind: "global", number: parameter.number, bank: section.bank };
    const label = prefix + parameter.number;
    const named = motor !== undefined && motors > 1;  // the motor said where there are more
    return {
      key: keyOf(address),
      label: label,
      title: named ? label + " (motor " + motor + ")" : label,
      curveName: label.replace(/ /g, "") + (named ? "_m" + motor : ""),
      motor: motor,
      section: section.title + (named ? ", motor " + motor : ""),
      name: parameter.name,
      unit: parameter.unit,
      range: parameter.min + " … " + parameter.max,
      access: parameter.access,
      defaultValue: parameter.default,
      writable: parameter.access.includes("W"),
      readable: parameter.access.includes("R"),
      storable: parameter.access.includes("E"),
      address: address,
      description: parameter.description,
    };
  }

  // A row of the module's global parameters or objects, or an axis parameter of `motor`.
  function ofMotor(row, motor) {
    return row.motor === undefined || row.motor === motor;
  }

  // --- Parameters / objects ------------------------------------------------------------------------

  function applyFilter() {
    const text = $("filter").value.trim().toLowerCase();
    state.shown = state.rows.filter((row) => ofMotor(row, state.motor) && (!text || row.name.toLowerCase().includes(text) ||
      row.label.toLowerCase().includes(text) || row.label.toLowerCase().replace(/^(ap|gp) /, "") === text));
    renderTable();
    subscribeShown();
  }

  function renderTable() {
    const body = $("parameters").tBodies[0];
    const fragment = document.createDocumentFragment();
    let section = null;
    for (const row of state.shown) {
      if (row.section !== section) {
        section = row.section;
        const header = document.createElement("tr");
        header.className = "section";
        const cell = document.createElement("th");
        cell.colSpan = 9;
        cell.textContent = section;
        header.appendChild(cell);
        fragment.appendChild(header);
      }
      fragment.appendChild(rowElement(row));
    }
    body.replaceChildren(fragment);
  }

  function cell(text, className) {
    const element = document.createElement("td");
    element.textContent = text === undefined ? "" : String(text);
    if (className) element.className = className;
    return element;
  }

  function rowElement(row) {
    const tr = document.createElement("tr");
    tr.dataset.key = row.key;
    if (row.description) tr.title = row.description;
    tr.append(cell(row.label, "number"), cell(row.name, "name"), cell(row.unit), cell(row.range, "range"),
      cell(row.access), cell(row.defaultValue, "default"));
    const valueCell = document.createElement("td");
    valueCell.className = "value";
    const input = document.createElement("input");
    input.type = "text";
    input.inputMode = "numeric";
    input.readOnly = !row.writable;
    input.setAttribute("aria-label", "Value of " + row.label);
    input.dataset.key = row.key;
    input.addEventListener("keydown", (event) => {
      if (event.key === "Enter" && row.writable) {
        setValue(row, input.value, tr);
        input.blur();
      } else if (event.key === "Escape") {
        input.value = input.dataset.live || "";
        input.blur();
      }
    });
    valueCell.appendChild(input);
    tr.appendChild(valueCell);
    tr.appendChild(cell("", "reply"));
    const actions = document.createElement("td");
    actions.className = "actions";
    if (row.readable) actions.appendChild(button("Read", () => readValue(row, tr)));
    if (row.storable) {
      actions.appendChild(button("Store", () => storeRow(row, "store", tr)));
      actions.appendChild(button("Restore", () => storeRow(row, "restore", tr)));
    }
    tr.appendChild(actions);
    return tr;
  }

  function button(text, onClick) {
    const element = document.createElement("button");
    element.type = "button";
    element.textContent = text;
    element.addEventListener("click", onClick);
    return element;
  }

  function replyText(reply) {
    if (reply.error) return reply.error;
    if (reply.abort) return "abort " + reply.abort + (reply.abort_text ? " (" + reply.abort_text + ")" : "");
    if (reply.status !== undefined) return reply.status + " " + reply.status_name;
    return reply.ok ? "ok" : "failed";
  }

  function showReply(tr, reply) {
    const target = tr.querySelector(".reply");
    target.textContent = replyText(reply);
    target.classList.toggle("error", !reply.ok);
    tr.dataset.reply = reply.ok ? "ok" : "error";
  }

  function setValue(row, text, tr) {
    const value = Number(text.trim());
    if (!Number.isInteger(value)) {
      showReply(tr, { ok: false, error: "not an integer" });
      return;
    }
    request(Object.assign({ op: "set", value: value }, row.address), (reply) => {
      showReply(tr, reply);
      readValue(row, tr, true);
    });
  }

  function readValue(row, tr, keepReply) {
    request(Object.assign({ op: "get" }, row.address), (reply) => {
      if (!keepReply) showReply(tr, reply);
      if (reply.ok) showValue(row.key, reply.value !== undefined ? reply.value : reply.text);
    });
  }

  function storeRow(row, op, tr) {
    request(Object.assign({ op: op }, row.address), (reply) => {
      showReply(tr, reply);
      if (op === "restore") readValue(row, tr, true);
    });
  }

  function storeShown(op) {
    const module = currentModule();
    if (!module) return;
    if (isCanopen()) {
      request({ op: op, module: module.module }, (reply) => { $("live-note").textContent = op + " (1010/1011 sub 1): " + replyText(reply); });
      return;
    }
    // One at a time: the server answers a session's requests but keeps only so many waiting.
    const rows = state.shown.filter((row) => row.storable);
    const next = (i) => {
      if (i >= rows.length) return;
      const tr = document.querySelector('tr[data-key="' + rows[i].key + '"]');
      request(Object.assign({ op: op }, rows[i].address), (reply) => {
        if (tr) showReply(tr, reply);
        if (tr && op === "restore") readValue(rows[i], tr, true);
        next(i + 1);
      });
    };
    next(0);
  }

  // Live values: the readable rows shown first, as many as the server subscribes.
  function subscribeShown() {
    const limit = isCanopen() ? CANOPEN_MAX_LIVE_ROWS : MAX_LIVE_ROWS;
    const live = state.shown.filter((row) => row.readable && currentModule().protocol !== "none").slice(0, limit);
    state.liveKeys = new Set(live.map((row) => row.key));
    $("live-note").textContent = live.length < state.shown.filter((row) => row.readable).length
      ? "live values for the first " + live.length + " rows; filter to see others" : "";
    request({ op: "subscribe", rate_hz: isCanopen() ? CANOPEN_LIVE_RATE_HZ : LIVE_RATE_HZ,
      items: live.map((row) => row.address) });
  }

  function onUpdate(message) {
    $("sim-time").textContent = "t = " + (message.sim_time_us / 1e6).toFixed(3) + " s";
    // Each entry by the address it echoes: a push of the subscription before (another motor's
    // rows, another module's) lands nowhere.
    message.values.forEach((entry) => {
      const key = keyOf(entry);
      if (!state.liveKeys.has(key) || entry.module !== state.module) return;
      if (entry.value !== undefined) showValue(key, entry.value);
      else if (entry.text !== undefined) showValue(key, entry.text);
    });
  }

  function showValue(key, value) {
    const input = document.querySelector('input[data-key="' + key + '"]');
    if (!input) return;
    const text = String(value);
    const changed = input.dataset.live !== undefined && input.dataset.live !== text;
    input.dataset.live = text;
    if (document.activeElement !== input) input.value = text;
    if (changed) {
      const tr = input.closest("tr");
      tr.classList.remove("changed");
      void tr.offsetWidth;  // restarts the highlight's animation
      tr.classList.add("changed");
    }
  }

  // --- Direct mode console -----------------------------------------------------------------------

  function logLine(kind, text) {
    const log = $("console-log");
    const item = document.createElement("li");
    item.className = kind;
    item.textContent = text;
    log.appendChild(item);
    while (log.children.length > 500) log.removeChild(log.firstChild);
    log.scrollTop = log.scrollHeight;
  }

  function parseNumber(text) {
    const trimmed = String(text).trim();
    if (/^-?0x[0-9a-f]+$/i.test(trimmed)) return (trimmed.startsWith("-") ? -1 : 1) * parseInt(trimmed.replace("-", ""), 16);
    return /^-?\d+$/.test(trimmed) ? Number(trimmed) : NaN;
  }

  // An index as the console takes it: hex without a prefix, like the manuals write indices.
  function parseIndex(text) {
    const trimmed = String(text).trim();
    return /^(0x)?[0-9a-f]{1,4}$/i.test(trimmed) ? parseInt(trimmed.replace(/^0x/i, ""), 16) : NaN;
  }

  function runCommand(line) {
    const module = currentModule();
    if (!module) return;
    logLine("command", "> " + line);
    if (!isCanopen()) {
      request({ op: "tmcl", module: module.module, text: line }, (reply) => {
        if (reply.version) logLine("reply", "version " + reply.version);
        else if (reply.replied === false) logLine("reply", "sent; no reply");
        else logLine(reply.ok ? "reply" : "error", reply.status !== undefined
          ? "status " + reply.status + " (" + reply.status_name + ") value " + reply.value : replyText(reply));
      });
      return;
    }
    const words = line.trim().split(/[\s,]+/);
    const verb = (words[0] || "").toLowerCase();
    if (verb === "nmt") return sendNmt(words[1] || "");
    if (verb === "r" || verb === "read") return sdoRead(words[1], words[2] || "0");
    if (verb === "w" || verb === "write") return sdoWrite(words[1], words[2] || "0", words[3]);
    logLine("error", "CANopen commands: r INDEX SUB · w INDEX SUB VALUE · nmt start|stop|pre-operational|reset-node|reset-communication");
  }

  function sdoReply(what) {
    return (reply) => {
      let text = what + ": " + replyText(reply);
      if (reply.ok && reply.value !== undefined) text = what + " = " + reply.value + " (0x" + (reply.data || "") + ")";
      if (reply.ok && reply.text !== undefined) text = what + " = \"" + reply.text + "\"";
      logLine(reply.ok ? "reply" : "error", text);
    };
  }

  function sdoRead(indexText, subText) {
    const index = parseIndex(indexText), sub = parseNumber(subText);
    if (Number.isNaN(index) || Number.isNaN(sub)) return logLine("error", "index (hex) and sub-index expected");
    request({ op: "sdo_read", module: currentModule().module, index: index, sub: sub },
      sdoReply("read " + indexText + "." + subText));
  }

  function sdoWrite(indexText, subText, valueText) {
    const index = parseIndex(indexText), sub = parseNumber(subText), value = parseNumber(valueText);
    if (Number.isNaN(index) || Number.isNaN(sub) || Number.isNaN(value)) {
      return logLine("error", "index (hex), sub-index and value expected");
    }
    request({ op: "sdo_write", module: currentModule().module, index: index, sub: sub, value: value },
      sdoReply("write " + indexText + "." + subText));
  }

  function sendNmt(command) {
    request({ op: "nmt", module: currentModule().module, command: command },
      (reply) => logLine(reply.ok ? "reply" : "error", "NMT " + command + ": " + replyText(reply)));
  }

  function onConsoleKey(event) {
    const input = $("console-input");
    if (event.key === "ArrowUp" || event.key === "ArrowDown") {
      if (state.history.length === 0) return;
      event.preventDefault();
      state.historyIndex += event.key === "ArrowUp" ? -1 : 1;
      state.historyIndex = Math.max(0, Math.min(state.history.length, state.historyIndex));
      input.value = state.history[state.historyIndex] || "";
    }
  }

  function onConsoleSubmit(event) {
    event.preventDefault();
    const input = $("console-input");
    const line = input.value.trim();
    if (!line) return;
    if (state.history[state.history.length - 1] !== line) state.history.push(line);
    if (state.history.length > HISTORY_LENGTH) state.history.shift();
    state.historyIndex = state.history.length;
    input.value = "";
    runCommand(line);
  }

  // --- Scope -------------------------------------------------------------------------------------

  function scopeRows() {
    const module = currentModule();
    if (!module || module.protocol === "none") return [];
    return state.rows.filter((row) => row.readable);
  }

  // A new module: nothing picked, the rates it can take.
  function resetScopeChoices() {
    state.scope.picked = [];
    const rates = isCanopen() ? CANOPEN_SCOPE_RATES_HZ : SCOPE_RATES_HZ;
    const chosen = isCanopen() ? CANOPEN_SCOPE_DEFAULT_RATE_HZ : SCOPE_DEFAULT_RATE_HZ;
    const select = $("scope-rate");
    select.replaceChildren();
    for (const rate of rates) select.add(new Option(rate + " /s", String(rate), false, rate === chosen));
    renderScopeChoices();
  }

  // The module's readable rows (the Parameters view's list) as check boxes; picked ones first.
  function renderScopeChoices() {
    const text = $("scope-filter").value.trim().toLowerCase();
    const picked = state.scope.picked;
    const rows = scopeRows();
    const shown = rows.filter((row) => picked.includes(row.key) || (ofMotor(row, state.scope.motor) &&
      (!text || row.name.toLowerCase().includes(text) || row.label.toLowerCase().includes(text))));
    shown.sort((a, b) => (picked.includes(b.key) ? 1 : 0) - (picked.includes(a.key) ? 1 : 0));
    const fragment = document.createDocumentFragment();
    for (const row of shown) {
      const item = document.createElement("li");
      const label = document.createElement("label");
      const box = document.createElement("input");
      box.type = "checkbox";
      box.dataset.key = row.key;
      box.checked = picked.includes(row.key);
      box.disabled = !box.checked && picked.length >= SCOPE_MAX_CURVES;
      box.addEventListener("change", () => pickCurve(row.key, box.checked));
      const text = document.createElement("span");
      text.textContent = row.title + " " + row.name + (row.unit && !isCanopen() ? " (" + row.unit + ")" : "");
      label.append(box, " ", text);
      item.appendChild(label);
      fragment.appendChild(item);
    }
    $("scope-choices").replaceChildren(fragment);
    showScopeNote();
  }

  function pickCurve(key, picked) {
    const list = state.scope.picked.filter((k) => k !== key);
    if (picked && list.length < SCOPE_MAX_CURVES) list.push(key);
    state.scope.picked = list;
    renderScopeChoices();
  }

  function showScopeNote(text) {
    const scope = state.scope;
    if (text === undefined) {
      text = scope.running ? "running, updates: " + scope.updates
        : scope.picked.length + " of at most " + SCOPE_MAX_CURVES + " curves picked";
    }
    $("scope-note").textContent = text;
    $("scope-start").disabled = scope.running || scope.picked.length === 0;
    $("scope-stop").disabled = !scope.running;
    // Rate and window belong to a run: they apply at the next Start.
    $("scope-rate").disabled = scope.running;
    $("scope-window").disabled = scope.running;
  }

  // Start: a fresh plot of the picked curves, fed by a session of its own subscribed to them.
  function startScope() {
    const module = currentModule();
    const rows = state.scope.picked.map((key) => state.rows.find((row) => row.key === key)).filter(Boolean);
    if (!module || rows.length === 0 || state.scope.running) return;
    const scope = state.scope;
    if (scope.instance) scope.instance.destroy();
    scope.instance = MotwinScope.create($("scope-plot"), {
      series: rows.map((row) => ({
        name: row.curveName,
        label: row.title + " " + row.name,
        unit: isCanopen() ? "" : row.unit,  // a CANopen dictionary names types, not units
      })),
      windowSeconds: Number($("scope-window").value),
      title: module.name,
      // Below the picker, with its toolbar, title and legend, in the window (at 1280x800 too).
      height: Math.max(180, Math.min(480, Math.floor(window.innerHeight - $("scope-plot").getBoundingClientRect().top - 150))),
    });
    const rate = Number($("scope-rate").value);
    const items = rows.map((row) => row.address);
    scope.socket = openSession((socket) => scope.socket === socket, {
      open: (socket) => socket.send(JSON.stringify({ id: 1, op: "subscribe", rate_hz: rate, items: items })),
      message: (message) => {
        if (message.id === 1 && !message.ok) return stopScope("refused: " + (message.error || "failed"));
        if (message.push !== "update") return;
        scope.updates++;
        scope.instance.push(message.sim_time_us / 1e6, message.values.map(curveValue));
        if (scope.updates % 10 === 1) showScopeNote();
      },
      close: () => stopScope("connection closed"),
    });
    scope.running = true;
    scope.updates = 0;
    showScopeNote();
  }

  // A number, or null (a gap) for a value the module refused or that is not a number.
  function curveValue(entry) {
    if (entry.error || entry.abort || (entry.status !== undefined && entry.status !== 100 && entry.status !== 101)) return null;
    return typeof entry.value === "number" ? entry.value : null;
  }

  // Stop: the session closes, and with it its subscription; the plot stays for zoom and export.
  function stopScope(why) {
    const scope = state.scope;
    if (!scope.running) return;
    const socket = scope.socket;
    scope.socket = null;
    scope.running = false;
    closeSession(socket);
    showScopeNote((why || "stopped") + "; updates: " + scope.updates);
  }

  // --- CANopen -----------------------------------------------------------------------------------
  // The node's NMT state (what the master heard: the small `nmt_state` op), each axis's CiA-402
  // words live through a session of its own (like the Scope's, so that the Parameters view's
  // subscription stays), the error register and 1003, and the PDO mappings read by SDO.

  const CANOPEN_VIEW_RATE_HZ = 10;
  const NMT_POLL_MS = 1000;
  // CiA-402 state from the statusword: mask, value, name (CiA-402 table 30).
  const CIA402_STATES = [
    [0x4F, 0x00, "Not ready to switch on"], [0x4F, 0x40, "Switch on disabled"],
    [0x6F, 0x21, "Ready to switch on"], [0x6F, 0x23, "Switched on"], [0x6F, 0x27, "Operation enabled"],
    [0x6F, 0x07, "Quick stop active"], [0x4F, 0x0F, "Fault reaction active"], [0x4F, 0x08, "Fault"],
  ];
  const STATUSWORD_BITS = ["ready to switch on", "switched on", "operation enabled", "fault", "voltage enabled",
    "quick stop", "switch on disabled", "warning", "manufacturer 8", "remote", "target reached",
    "internal limit active", "mode specific 12", "mode specific 13", "manufacturer 14", "manufacturer 15"];
  const MODES = { 0: "none", 1: "profile position", 2: "velocity", 3: "profile velocity", 4: "profile torque",
    6: "homing", 7: "interpolated position", 8: "cyclic sync position", 9: "cyclic sync velocity",
    10: "cyclic sync torque" };
  const ERROR_REGISTER_BITS = ["generic", "current", "voltage", "temperature", "communication",
    "device profile", "reserved", "manufacturer"];
  // Offsets from an axis's controlword (6040 + n × stride) of what the view shows.
  const AXIS_OBJECTS = [["statusword", 0x01], ["controlword", 0x00], ["mode", 0x21], ["position", 0x24],
    ["velocity", 0x2C]];

  const canopen = {
    socket: null,     // the view's own session while it is shown
    pollTimer: null,
    axes: [],         // [{axis, controlword index}]
    items: [],        // [{axis, what}] in the order subscribed
    pdoGeneration: 0, // a newer Read (or leaving the view) abandons an older one
    monitor: { paused: false, frames: 0, dropped: 0, shown: 0 },
    emcyHeard: [],       // EMCYs of the chosen node heard on the bus (no 1003 to read)
    emcyFrom1003: false,
    viewGeneration: 0,
  };

  function hex4(index) {
    return index.toString(16).toUpperCase().padStart(4, "0");
  }

  function ask(message) {
    return new Promise((resolve) => request(message, resolve));
  }

  function objectOf(module, index, sub) {
    for (const section of module.sections) {
      if (section.kind !== "objects") continue;
      const found = section.objects.find((object) => object.index === index && object.sub === sub);
      if (found) return found;
    }
    return null;
  }

  function canopenObjects(module) {
    return module.sections.filter((section) => section.kind === "objects").flatMap((section) => section.objects);
  }

  function cia402State(statusword) {
    const found = CIA402_STATES.find(([mask, value]) => (statusword & mask) === value);
    return found ? found[2] : "unknown";
  }

  function bitChips(value, names, faultBits) {
    const fragment = document.createDocumentFragment();
    names.forEach((name, bit) => {
      if (!(value & (1 << bit))) return;
      const chip = document.createElement("span");
      chip.className = "bit" + (faultBits.includes(bit) ? " fault" : "");
      chip.textContent = bit + " " + name;
      fragment.appendChild(chip);
    });
    return fragment;
  }

  function showNmtState(module) {
    const element = $("canopen-nmt-state");
    const text = module && module.nmt_state ? module.nmt_state : "not heard yet";
    element.textContent = text;
    element.dataset.state = module && module.nmt_state ? module.nmt_state : "";
  }

  function startCanopenView() {
    stopCanopenView();
    const module = currentModule();
    const reachable = module && isCanopen();
    $("canopen-none").hidden = reachable;
    $("canopen-body").hidden = !reachable;
    if (!reachable) return;
    showNmtState(module);
    $("canopen-note").textContent = "";
    // The axes: each statusword of the dictionary (6041, 6841, 7041 ...).
    canopen.axes = canopenObjects(module).filter((object) => object.name === "Statusword" && object.sub === 0)
      .map((object) => ({ axis: object.axis, base: object.index - 1 }));
    canopen.items = [];
    const items = [];
    for (const axis of canopen.axes) {
      for (const [what, offset] of AXIS_OBJECTS) {
        if (!objectOf(module, axis.base + offset, 0)) continue;
        canopen.items.push({ axis: axis.axis, what: what });
        items.push({ module: module.module, index: axis.base + offset, sub: 0 });
      }
    }
    canopen.items.push({ axis: null, what: "errors" });
    items.push({ module: module.module, index: 0x1001, sub: 0 });
    renderAxes();
    canopen.monitor.frames = 0;
    canopen.monitor.dropped = 0;
    canopen.emcyHeard = [];
    canopen.emcyFrom1003 = false;
    showMonitorNote();
    let nextId = 2;
    canopen.socket = openSession((socket) => canopen.socket === socket, {
      open: (socket) => {
        socket.send(JSON.stringify({ id: 1, op: "subscribe", rate_hz: CANOPEN_VIEW_RATE_HZ, items: items.slice(0, CANOPEN_MAX_LIVE_ROWS) }));
        socket.send(JSON.stringify({ id: 0, op: "monitor", enable: true }));
        // The NMT state by the small "nmt_state" op (not the whole "list" with every table).
        canopen.pollTimer = setInterval(() => {
          if (canopen.socket === socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify({ id: nextId++, op: "nmt_state" }));
        }, NMT_POLL_MS);
      },
      message: (message) => {
        if (message.push === "update") return onCanopenUpdate(message);
        if (message.push === "frames") return onFrames(message);
        if (message.id === 1 && !message.ok) $("canopen-note").textContent = "live values refused: " + replyText(message);
        if (message.id > 1 && message.ok && message.nodes) {
          showNmtState(message.nodes.find((node) => node.module === module.module));
        }
      },
      close: () => {
        stopCanopenView();
        $("canopen-note").textContent = "live values: connection closed";
      },
    });
    readErrors();
    readPdos();
  }

  function stopCanopenView() {
    canopen.pdoGeneration++;
    canopen.viewGeneration++;
    if (canopen.pollTimer) clearInterval(canopen.pollTimer);
    canopen.pollTimer = null;
    const socket = canopen.socket;
    canopen.socket = null;
    closeSession(socket);
  }

  function renderAxes() {
    const fragment = document.createDocumentFragment();
    for (const axis of canopen.axes) {
      const tr = document.createElement("tr");
      tr.dataset.axis = axis.axis;
      tr.append(cell(axis.axis + " (" + hex4(axis.base + 1) + ")"), cell("", "statusword"), cell("", "cia402-state"),
        cell("", "bits"), cell("", "controlword"), cell("", "mode"), cell("", "position"), cell("", "velocity"));
      fragment.appendChild(tr);
    }
    $("canopen-axes").tBodies[0].replaceChildren(fragment);
  }

  function onCanopenUpdate(message) {
    message.values.forEach((entry, i) => {
      const item = canopen.items[i];
      if (!item || entry.value === undefined) return;
      const value = entry.value;
      if (item.what === "errors") return showErrorRegister(value);
      const tr = document.querySelector('#canopen-axes tr[data-axis="' + item.axis + '"]');
      if (!tr) return;
      const set = (name, text) => { tr.querySelector("td." + name).textContent = text; };
      if (item.what === "statusword") {
        set("statusword", "0x" + hex4(value));
        set("cia402-state", cia402State(value));
        tr.querySelector("td.bits").replaceChildren(bitChips(value, STATUSWORD_BITS, [3, 7]));
      } else if (item.what === "controlword") {
        set("controlword", "0x" + hex4(value) + " (" + value + ")");
      } else if (item.what === "mode") {
        set("mode", value + " " + (MODES[value] || "manufacturer/unknown"));
      } else {
        set(item.what, String(value));
      }
    });
  }

  function showErrorRegister(value) {
    $("canopen-error-register").textContent = "0x" + value.toString(16).toUpperCase().padStart(2, "0");
    const bits = $("canopen-error-bits");
    bits.replaceChildren(bitChips(value, ERROR_REGISTER_BITS, [0]));
    if (value === 0) bits.textContent = "no error";
  }

  // 1001 and the pre-defined error field 1003 (sub 0: how many, then newest first).
  async function readErrors() {
    const module = currentModule();
    const generation = canopen.viewGeneration;
    const list = $("canopen-emcy");
    const line = (text, className) => {
      const item = document.createElement("li");
      item.textContent = text;
      if (className) item.className = className;
      list.appendChild(item);
    };
    const register = await ask({ op: "sdo_read", module: module.module, index: 0x1001, sub: 0 });
    if (generation !== canopen.viewGeneration) return;
    if (register.ok) showErrorRegister(register.value);
    const count = await ask({ op: "sdo_read", module: module.module, index: 0x1003, sub: 0 });
    if (generation !== canopen.viewGeneration) return;
    list.replaceChildren();
    canopen.emcyFrom1003 = count.ok;
    if (!count.ok) {
      // No pre-defined error field (the TMCM-3216 has none): the EMCYs the node sent on the bus
      // since the view opened, newest first, as the monitor heard them.
      line("EMCY history (1003): " + replyText(count) + "; EMCYs heard on the bus since the view opened:", "info");
      return showEmcyHeard();
    }
    if (count.value === 0) return line("EMCY history (1003): empty", "info");
    for (let sub = 1; sub <= count.value; sub++) {
      const entry = await ask({ op: "sdo_read", module: module.module, index: 0x1003, sub: sub });
      if (generation !== canopen.viewGeneration) return;
      if (!entry.ok) {
        line("1003." + sub + ": " + replyText(entry));
        continue;
      }
      const code = entry.value & 0xFFFF, extra = entry.value >>> 16;
      line("EMCY 0x" + hex4(code) + (extra ? ", additional 0x" + extra.toString(16).toUpperCase() : ""));
    }
  }

  function showEmcyHeard() {
    const list = $("canopen-emcy");
    while (list.children.length > 1) list.lastChild.remove();
    if (canopen.emcyHeard.length === 0) {
      const item = document.createElement("li");
      item.textContent = "none";
      list.appendChild(item);
    }
    for (const emcy of canopen.emcyHeard.slice().reverse()) {
      const item = document.createElement("li");
      item.className = "emcy-heard";
      item.textContent = (emcy.t_us / 1e6).toFixed(4) + " s: EMCY 0x" + hex4(emcy.code) + ", register 0x" +
        emcy.register.toString(16).toUpperCase().padStart(2, "0");
      list.appendChild(item);
    }
  }

  // An EMCY of the chosen node in the monitor's frames (COB-ID 0x80 + node; 0x80 is SYNC).
  function noteEmcys(frames) {
    const module = currentModule();
    if (!module || module.node_id === undefined) return;
    let heard = false;
    for (const frame of frames) {
      if (frame.extended || frame.rtr || frame.id !== 0x80 + module.node_id) continue;
      const bytes = bytesOf(frame.data);
      if (bytes.length < 3) continue;
      canopen.emcyHeard.push({ t_us: frame.t_us, code: u16(bytes, 0), register: bytes[2] });
      heard = true;
    }
    while (canopen.emcyHeard.length > EMCY_HEARD_KEPT) canopen.emcyHeard.shift();
    if (heard && !canopen.emcyFrom1003 && $("canopen-emcy").children.length > 0) showEmcyHeard();
  }

  // The PDOs the dictionary has: communication 1400.. (RPDO) / 1800.. (TPDO), mapping + 0x200.
  async function readPdos() {
    const module = currentModule();
    const generation = ++canopen.pdoGeneration;
    const body = $("canopen-pdos").tBodies[0];
    body.replaceChildren();
    const communication = canopenObjects(module).filter((object) => object.sub === 1 &&
      ((object.index >= 0x1400 && object.index < 0x1600) || (object.index >= 0x1800 && object.index < 0x1A00)));
    communication.sort((a, b) => (a.axis - b.axis) || (b.index >= 0x1800) - (a.index >= 0x1800) || a.index - b.index);
    const read = (index, sub) => ask({ op: "sdo_read", module: module.module, index: index, sub: sub });
    let done = 0;
    for (const object of communication) {
      const name = pdoName(object.name);
      const tr = document.createElement("tr");
      tr.dataset.pdo = hex4(object.index + 0x200);
      tr.append(cell(name + " (" + hex4(object.index) + " / " + hex4(object.index + 0x200) + ")"), cell(object.axis),
        cell("", "cob-id"), cell("", "valid"), cell("", "transmission"), cell("", "mapped"));
      body.appendChild(tr);
      const cobId = await read(object.index, 1);
      const transmission = await read(object.index, 2);
      const count = await read(object.index + 0x200, 0);
      if (generation !== canopen.pdoGeneration) return;
      if (cobId.ok) {
        tr.querySelector("td.cob-id").textContent = "0x" + (cobId.value & 0x7FF).toString(16).toUpperCase();
        tr.querySelector("td.valid").textContent = (cobId.value >>> 31) ? "no" : "yes";
      } else {
        tr.querySelector("td.cob-id").textContent = replyText(cobId);
      }
      tr.querySelector("td.transmission").textContent = transmission.ok ? transmissionText(transmission.value) : replyText(transmission);
      const mapped = [];
      if (count.ok) {
        for (let sub = 1; sub <= count.value; sub++) {
          const entry = await read(object.index + 0x200, sub);
          if (generation !== canopen.pdoGeneration) return;
          mapped.push(entry.ok ? mappingText(module, entry.value) : replyText(entry));
        }
      }
      tr.querySelector("td.mapped").textContent = count.ok ? (mapped.join(" · ") || "nothing mapped") : replyText(count);
      done++;
      $("canopen-pdo-note").textContent = done + " of " + communication.length + " read";
    }
  }

  // "TPDO 1" from the communication object's name: "TPDO 1 communication parameter: COB-ID used by
  // TPDO" (the TMCM-3216) or, as Trinamic's EDS names them (the TMCM-1636), "Transmit PDO
  // Communication Parameter 1: COB-ID".
  function pdoName(name) {
    const eds = /^(Receive|Transmit) PDO Communication Parameter (\d+)/i.exec(name);
    if (eds) return (eds[1].toLowerCase() === "receive" ? "RPDO " : "TPDO ") + eds[2];
    return name.replace(/ communication parameter.*$/, "");
  }

  // --- Bus monitor: the "frames" pushes of the `monitor` op, decoded by the predefined
  // connection set of CiA-301 (COB-ID = function code + node ID).

  const MONITOR_ROWS = 500;
  const EMCY_HEARD_KEPT = 50;
  const NMT_COMMANDS = { 1: "start", 2: "stop", 128: "enter pre-operational", 129: "reset node", 130: "reset communication" };
  const HEARTBEAT_STATES = { 0: "boot-up", 4: "stopped", 5: "operational", 127: "pre-operational" };
  const SDO_REQUESTS = { 0: "download segment", 1: "initiate download", 2: "initiate upload", 3: "upload segment", 4: "abort" };
  const SDO_RESPONSES = { 0: "upload segment", 1: "download segment", 2: "initiate upload", 3: "initiate download", 4: "abort" };

  function bytesOf(hex) {
    const bytes = [];
    for (let i = 0; i + 1 < hex.length; i += 2) bytes.push(parseInt(hex.substr(i, 2), 16));
    return bytes;
  }

  function u16(bytes, at) { return bytes[at] | (bytes[at + 1] << 8); }
  function u32(bytes, at) { return (u16(bytes, at) | (u16(bytes, at + 2) << 16)) >>> 0; }

  function sdoText(bytes, names) {
    const specifier = bytes[0] >> 5;
    let text = names[specifier] || "specifier " + specifier;
    if (specifier === 4) return text + " " + hex4(u16(bytes, 1)) + "." + bytes[3] + " code 0x" + u32(bytes, 4).toString(16).toUpperCase().padStart(8, "0");
    if (names === SDO_REQUESTS ? (specifier === 1 || specifier === 2) : (specifier === 2 || specifier === 3)) {
      text += " " + hex4(u16(bytes, 1)) + "." + bytes[3];
      if ((bytes[0] & 3) === 3) text += " = " + u32(bytes, 4) % Math.pow(2, 8 * (4 - ((bytes[0] >> 2) & 3)));
    }
    return text;
  }

  // [service, meaning] of a frame.
  function decodeFrame(frame) {
    const id = frame.id, bytes = bytesOf(frame.data);
    if (frame.extended) return ["extended", ""];
    if (id === 0) return ["NMT", (NMT_COMMANDS[bytes[0]] || "command " + bytes[0]) + (bytes[1] ? " node " + bytes[1] : " all nodes")];
    if (id === 0x80) return ["SYNC", bytes.length ? "counter " + bytes[0] : ""];
    const node = id & 0x7F, fn = id & 0x780;
    if (fn === 0x80) return ["EMCY " + node, bytes.length >= 3 ? "error 0x" + hex4(u16(bytes, 0)) + ", register 0x" + bytes[2].toString(16).toUpperCase().padStart(2, "0") : ""];
    if (id === 0x100) return ["TIME", ""];
    if (fn >= 0x180 && fn <= 0x500) {
      const number = ((fn - 0x100) >> 8) + (fn & 0x80 ? 1 : 0);  // TPDO n: 0x180 + (n - 1) × 0x100, RPDO n: 0x200 + ...
      return [(fn & 0x80 ? "TPDO " : "RPDO ") + number + " node " + node, frame.rtr ? "remote request" : ""];
    }
    if (fn === 0x580) return ["SDO response " + node, sdoText(bytes, SDO_RESPONSES)];
    if (fn === 0x600) return ["SDO request " + node, sdoText(bytes, SDO_REQUESTS)];
    if (fn === 0x700) return ["Heartbeat " + node, frame.rtr ? "node guarding" : HEARTBEAT_STATES[bytes[0] & 0x7F] || "state " + (bytes[0] & 0x7F)];
    return ["other", ""];
  }

  function onFrames(message) {
    noteEmcys(message.frames);
    const monitor = canopen.monitor;
    monitor.frames += message.frames.length;
    monitor.dropped = message.dropped;
    if (!monitor.paused) {
      const hideSdo = $("monitor-hide-sdo").checked;
      const body = $("monitor").tBodies[0];
      const fragment = document.createDocumentFragment();
      for (const frame of message.frames) {
        const [service, meaning] = decodeFrame(frame);
        if (hideSdo && service.startsWith("SDO")) continue;
        const tr = document.createElement("tr");
        tr.append(cell((frame.t_us / 1e6).toFixed(4)), cell("0x" + frame.id.toString(16).toUpperCase().padStart(3, "0")),
          cell(service, "service"), cell(frame.rtr ? "RTR" : frame.data.replace(/(..)(?!$)/g, "$1 ")), cell(meaning, "meaning"));
        fragment.appendChild(tr);
      }
      const wrap = body.closest(".table-wrap");
      const atBottom = wrap.scrollTop + wrap.clientHeight >= wrap.scrollHeight - 4;
      body.appendChild(fragment);
      while (body.rows.length > MONITOR_ROWS) body.deleteRow(0);
      if (atBottom) wrap.scrollTop = wrap.scrollHeight;
    }
    showMonitorNote();
  }

  function showMonitorNote() {
    const monitor = canopen.monitor;
    $("monitor-note").textContent = (monitor.paused ? "paused · " : "") + monitor.frames + " frames" +
      (monitor.dropped ? " · " + monitor.dropped + " dropped by the server (the page was behind)" : "");
    $("monitor-pause").textContent = monitor.paused ? "Run" : "Pause";
  }

  function transmissionText(type) {
    if (type === 0) return "0 synchronous (acyclic)";
    if (type <= 240) return type + " every " + (type === 1 ? "" : type + "th ") + "SYNC";
    if (type === 252 || type === 253) return type + " RTR only";
    return type + " event driven";
  }

  // A mapping entry: index (16 bits), sub (8), length in bits (8); named from the dictionary.
  function mappingText(module, entry) {
    const index = entry >>> 16, sub = (entry >>> 8) & 0xFF, bits = entry & 0xFF;
    const object = objectOf(module, index, sub);
    const name = object ? object.name : index < 8 ? "dummy" : "not in the dictionary";
    return hex4(index) + "." + sub + " " + name + " (" + bits + " bit)";
  }

  // --- Views -------------------------------------------------------------------------------------

  function showView(name) {
    if (name !== "scope") stopScope("left the Scope view");
    if (name !== "canopen") stopCanopenView();
    if (window.MotwinDatalogger) window.MotwinDatalogger.viewShown(name);
    if (name !== "world") window.MotwinWorld.stop();
    state.view = name;
    for (const tab of document.querySelectorAll("#tabs [role=tab]")) {
      tab.setAttribute("aria-selected", String(tab.dataset.view === name));
    }
    for (const view of document.querySelectorAll(".view")) view.hidden = view.id !== "view-" + name;
    if (name === "console") $("console-input").focus();
    if (name === "canopen") startCanopenView();
    if (name === "world") window.MotwinWorld.start(state.module);
    announceView();
  }

  // Views in files of their own (program.js) follow the chosen view and module by this event.
  function announceView() {
    document.dispatchEvent(new CustomEvent("motwin-view", { detail: { view: state.view, module: currentModule() } }));
  }

  function start() {
    for (const tab of document.querySelectorAll("#tabs [role=tab]")) {
      tab.addEventListener("click", () => showView(tab.dataset.view));
    }
    $("module-picker").addEventListener("change", (event) => chooseModule(Number(event.target.value)));
    $("filter").addEventListener("input", applyFilter);
    $("motor-picker").addEventListener("change", (event) => {
      state.motor = Number(event.target.value);
      applyFilter();
    });
    $("scope-motor").addEventListener("change", (event) => {
      state.scope.motor = Number(event.target.value);
      renderScopeChoices();
    });
    $("store-all").addEventListener("click", () => storeShown("store"));
    $("restore-all").addEventListener("click", () => storeShown("restore"));
    $("console-form").addEventListener("submit", onConsoleSubmit);
    $("scope-filter").addEventListener("input", renderScopeChoices);
    $("scope-start").addEventListener("click", startScope);
    $("scope-stop").addEventListener("click", () => stopScope("stopped"));
    $("console-input").addEventListener("keydown", onConsoleKey);
    $("sdo-read").addEventListener("click", () => sdoRead($("sdo-index").value, $("sdo-sub").value));
    $("sdo-write").addEventListener("click", () => sdoWrite($("sdo-index").value, $("sdo-sub").value, $("sdo-value").value));
    for (const nmt of document.querySelectorAll("[data-nmt]")) nmt.addEventListener("click", () => sendNmt(nmt.dataset.nmt));
    for (const nmt of document.querySelectorAll("[data-canopen-nmt]")) {
      nmt.addEventListener("click", () => request({ op: "nmt", module: currentModule().module, command: nmt.dataset.canopenNmt },
        (reply) => { $("canopen-note").textContent = "NMT " + nmt.dataset.canopenNmt + ": " + replyText(reply); }));
    }
    $("canopen-pdo-read").addEventListener("click", readPdos);
    $("monitor-pause").addEventListener("click", () => {
      canopen.monitor.paused = !canopen.monitor.paused;
      showMonitorNote();
    });
    $("monitor-clear").addEventListener("click", () => $("monitor").tBodies[0].replaceChildren());
    $("canopen-errors-read").addEventListener("click", () => { if (canopen.socket) readErrors(); });
    connect();
  }

  start();
})();
