// The console's Program view (docs/web-console.md "The page"): the stored TMCL program of a
// TMCL module read back and disassembled, one line per address, the line at the program counter
// highlighted; the application status live; run / continue / stop / step / reset; a source
// assembled and downloaded by the server's program ops. The view speaks through a WebSocket
// session of its own while it is shown, so the other views' subscriptions stay as they are.
// app.js tells it which view and module are chosen with a "motwin-view" event on document.
(function () {
  "use strict";

  const STATUS_PERIOD_MS = 100;  // one app_status after another, at most this often: ~10 a second

  const $ = (id) => document.getElementById(id);
  const view = {
    module: null,         // the module entry of "list" the view shows
    shown: false,
    socket: null,
    nextId: 1,
    waiting: new Map(),   // request id -> callback
    statusTimer: null,
    lines: [],            // program_read's instructions
    pc: null,
    selected: null,       // address picked in the listing
    status: null,         // the last app_status reply
    statusReplies: 0,
  };
  // For scripts and tests.
  window.motwinProgram = {
    get status() { return view.status; },
    get statusReplies() { return view.statusReplies; },
    get lines() { return view.lines; },
  };

  function reachable(module) {
    return module && module.protocol === "tmcl";
  }

  function note(text, isError) {
    const element = $("program-note");
    element.textContent = text;
    element.classList.toggle("error", Boolean(isError));
  }

  function replyText(reply) {
    if (reply.error) return reply.error;
    if (reply.status !== undefined) return "status " + reply.status + " " + reply.status_name;
    return reply.ok ? "ok" : "failed";
  }

  // --- The session ---------------------------------------------------------------------------------

  function ask(message, callback) {
    const socket = view.socket;
    if (!socket || socket.readyState !== WebSocket.OPEN) return false;
    const id = view.nextId++;
    message.id = id;
    message.module = view.module.module;
    view.waiting.set(id, callback);
    socket.send(JSON.stringify(message));
    return true;
  }

  function open() {
    close();
    const module = view.module;
    $("program-none").hidden = reachable(module);
    $("program-body").hidden = !reachable(module);
    if (!reachable(module)) return;
    view.socket = window.motwinSession.open((socket) => view.socket === socket, {
      open: () => {
        note("");
        readProgram();
        pollStatus();
      },
      message: (message) => {
        const callback = view.waiting.get(message.id);
        if (!callback) return;
        view.waiting.delete(message.id);
        callback(message);
      },
      close: () => {
        close();
        note("connection closed", true);
      },
    });
  }

  function close() {
    if (view.statusTimer) clearTimeout(view.statusTimer);
    view.statusTimer = null;
    view.waiting.clear();
    const socket = view.socket;
    view.socket = null;
    window.motwinSession.close(socket);
  }

  // --- Status --------------------------------------------------------------------------------------

  function pollStatus() {
    view.statusTimer = null;
    const asked = Date.now();
    const sent = ask({ op: "app_status" }, (reply) => {
      showStatus(reply);
      view.statusTimer = setTimeout(pollStatus, Math.max(0, STATUS_PERIOD_MS - (Date.now() - asked)));
    });
    if (!sent) view.statusTimer = setTimeout(pollStatus, STATUS_PERIOD_MS);
  }

  function showStatus(reply) {
    view.statusReplies++;
    if (!reply.ok) {
      $("program-mode").textContent = "–";
      note("status: " + replyText(reply), true);
      return;
    }
    view.status = reply;
    $("program-mode").textContent = reply.mode_name;
    $("program-mode").dataset.mode = reply.mode_name;
    $("program-pc").textContent = String(reply.program_counter);
    $("program-accumulator").textContent = String(reply.accumulator);
    $("program-x").textContent = String(reply.x_register);
    $("program-wait").textContent = reply.waiting ? "yes" : "no";
    $("program-stop-reason").textContent = reply.stop_reason === 0 ? "none"
      : reply.stop_reason_name + " at " + reply.stop_address;
    markPc(reply.program_counter);
  }

  function rowOf(address) {
    return $("program-lines").tBodies[0].querySelector('tr[data-address="' + address + '"]');
  }

  function markPc(pc) {
    if (pc === view.pc) return;
    const before = view.pc === null ? null : rowOf(view.pc);
    if (before) before.classList.remove("pc");
    view.pc = pc;
    const row = rowOf(pc);
    if (!row) return;
    row.classList.add("pc");
    // Keep the line in sight within the listing's own scroller (not the page's).
    const wrap = $("program-listing");
    const top = row.offsetTop - wrap.querySelector("thead").offsetHeight;
    if (top < wrap.scrollTop || row.offsetTop + row.offsetHeight > wrap.scrollTop + wrap.clientHeight) {
      wrap.scrollTop = Math.max(0, top - wrap.clientHeight / 3);
    }
  }

  // --- The stored program --------------------------------------------------------------------------

  function readProgram() {
    $("program-listing-note").textContent = "reading…";
    ask({ op: "program_read" }, (reply) => {
      if (!reply.ok) {
        $("program-listing-note").textContent = replyText(reply);
        return;
      }
      view.lines = reply.instructions;
      renderLines();
      const count = reply.instructions.length;
      $("program-listing-note").textContent = count + " instruction" + (count === 1 ? "" : "s") +
        (reply.end === "nop" ? " (up to the NOP that ends a download)" : reply.end === "memory_end" ? " (all of program memory)" : "");
    });
  }

  function renderLines() {
    const body = $("program-lines").tBodies[0];
    const rows = view.lines.map((line) => {
      const tr = document.createElement("tr");
      tr.dataset.address = line.address;
      for (const [text, className] of [[String(line.address), "address"], [line.label || "", "label"], [line.text, "text"]]) {
        const td = document.createElement("td");
        td.className = className;
        td.textContent = text;
        tr.appendChild(td);
      }
      tr.title = "command " + line.command + ", type " + line.type + ", motor/bank " + line.motor_bank + ", value " + line.value;
      if (line.address === view.selected) tr.classList.add("selected");
      return tr;
    });
    body.replaceChildren(...rows);
    const pc = view.pc;
    view.pc = null;
    if (pc !== null) markPc(pc);
  }

  function select(address) {
    const before = view.selected === null ? null : rowOf(view.selected);
    if (before) before.classList.remove("selected");
    view.selected = address;
    const row = rowOf(address);
    if (row) row.classList.add("selected");
    $("program-address").value = String(address);
  }

  // --- Run, stop, step, reset ----------------------------------------------------------------------

  function control(action) {
    const message = { op: "program_control", action: action };
    if (action === "run") {
      const address = Number($("program-address").value || "0");
      if (!Number.isInteger(address) || address < 0) return note("the start address is not a number", true);
      message.address = address;
    }
    const sent = ask(message, (reply) => {
      note(action + (action === "run" ? " from " + message.address : "") + ": " + replyText(reply), !reply.ok);
    });
    if (!sent) note("not connected", true);
  }

  // --- Assemble and download -----------------------------------------------------------------------

  function download() {
    const source = $("program-source").value;
    const message = { op: "program_download", source: source, file_name: view.fileName || "program.tmc" };
    if (view.includes && Object.keys(view.includes).length) message.files = view.includes;
    $("program-errors").replaceChildren();
    $("program-download").disabled = true;
    note("assembling and downloading…");
    const sent = ask(message, (reply) => {
      $("program-download").disabled = false;
      if (reply.errors) showErrors(reply.errors);
      if (reply.mismatches) {
        showErrors(reply.mismatches.map((mismatch) => ({
          text: "address " + mismatch.address + ": sent " + mismatch.sent.text + ", the module holds " + mismatch.held.text,
        })));
      }
      if (!reply.ok) return note("download: " + replyText(reply), true);
      note("downloaded " + reply.count + " instructions to addresses " + reply.start + ".." +
        (reply.start + reply.count - 1) + (reply.verified ? " and verified" : ""));
      readProgram();
    });
    if (!sent) {
      $("program-download").disabled = false;
      note("not connected", true);
    }
  }

  function showErrors(errors) {
    const list = $("program-errors");
    list.replaceChildren(...errors.map((error) => {
      const item = document.createElement("li");
      item.textContent = error.line ? error.file + " line " + error.line + (error.column ? ", column " + error.column : "") +
        ": " + error.message : error.text;
      if (error.line && error.file === (view.fileName || "program.tmc")) {
        item.dataset.line = error.line;
        item.tabIndex = 0;
        item.title = "Show the line";
      }
      return item;
    }));
  }

  // Selects source line `line` (1-based) in the text area.
  function showSourceLine(line) {
    const area = $("program-source");
    const lines = area.value.split("\n");
    let start = 0;
    for (let i = 0; i < line - 1 && i < lines.length; ++i) start += lines[i].length + 1;
    const end = start + (lines[line - 1] || "").length;
    area.focus();
    area.setSelectionRange(start, end);
  }

  async function loadFiles(files) {
    if (!files.length) return;
    const texts = await Promise.all(Array.from(files, (file) => file.text()));
    view.fileName = files[0].name;
    view.includes = {};
    for (let i = 1; i < files.length; ++i) view.includes[files[i].name] = texts[i];
    $("program-source").value = texts[0];
    const includes = Object.keys(view.includes);
    note("loaded " + view.fileName + (includes.length ? " with " + includes.join(", ") + " for #include" : ""));
  }

  // --- Hooks ---------------------------------------------------------------------------------------

  function onViewEvent(event) {
    const shown = event.detail.view === "program";
    const module = event.detail.module || null;
    const changed = !view.module || !module || module.module !== view.module.module || module.name !== view.module.name;
    if (changed && module) {
      view.lines = [];
      view.pc = null;
      view.selected = null;
      view.status = null;
      renderLines();
      $("program-listing-note").textContent = "";
      $("program-errors").replaceChildren();
      note("");
      for (const id of ["program-mode", "program-pc", "program-accumulator", "program-x", "program-wait", "program-stop-reason"]) {
        $(id).textContent = "–";
      }
    }
    view.module = module;
    if (shown && (!view.shown || changed || !view.socket)) open();
    if (!shown && view.shown) close();
    view.shown = shown;
  }

  function start() {
    document.addEventListener("motwin-view", onViewEvent);
    for (const action of ["run", "continue", "stop", "step", "reset"]) {
      $("program-" + action).addEventListener("click", () => control(action));
    }
    $("program-read").addEventListener("click", readProgram);
    $("program-download").addEventListener("click", download);
    $("program-file").addEventListener("change", (event) => loadFiles(event.target.files));
    $("program-lines").addEventListener("click", (event) => {
      const row = event.target.closest("tr[data-address]");
      if (row) select(Number(row.dataset.address));
    });
    $("program-errors").addEventListener("click", (event) => {
      const item = event.target.closest("li[data-line]");
      if (item) showSourceLine(Number(item.dataset.line));
    });
    $("program-errors").addEventListener("keydown", (event) => {
      const item = event.target.closest("li[data-line]");
      if (item && event.key === "Enter") showSourceLine(Number(item.dataset.line));
    });
  }

  start();
})();
