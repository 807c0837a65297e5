// A WebSocket session of one view of the console page (docs/web-console.md "The page"): the main
// connection, the Scope's, the CANopen view's, the datalogger mode's, the Program and World
// views' each keep their own, so that one view's requests never wait behind another's. Loaded
// before the views; they reach it as window.motwinSession.
(function (global) {
  "use strict";

  // The page's own server, with the token the page was opened with (non-loopback serves).
  function socketUrl() {
    const token = new URLSearchParams(location.search).get("token");
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    return scheme + "//" + location.host + "/ws" + (token ? "?token=" + encodeURIComponent(token) : "");
  }

  // Opens a session: `handlers.open(socket)` once open, `handlers.message(message)` with each
  // message parsed, `handlers.close()` when it ends, each only while `isCurrent(socket)` (the view
  // has not moved on to another session).
  function open(isCurrent, handlers) {
    const socket = new WebSocket(socketUrl(), "motwin");
    socket.addEventListener("open", () => {
      if (isCurrent(socket) && handlers.open) handlers.open(socket);
    });
    socket.addEventListener("message", (event) => {
      if (!isCurrent(socket)) return;
      let message;
      try {
        message = JSON.parse(event.data);
      } catch (error) {
        return;
      }
      handlers.message(message);
    });
    socket.addEventListener("close", () => {
      if (isCurrent(socket) && handlers.close) handlers.close();
    });
    return socket;
  }

  function close(socket) {
    // Closing a socket still connecting makes the browser log an error: close it once open.
    if (socket && socket.readyState === WebSocket.CONNECTING) socket.addEventListener("open", () => socket.close());
    else if (socket) socket.close();
  }

  global.motwinSession = { socketUrl, open, close };
})(window);
