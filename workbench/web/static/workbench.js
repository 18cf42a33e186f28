// The workbench page: xterm.js shows the app's screen from the WebSocket and sends the keys
// and the terminal's size back. Binary frames carry terminal bytes; text frames carry JSON
// (from the page: {"type": "resize", "cols", "rows"}; from the server: a notice to show).
(function () {
  "use strict";
  const body = document.body;
  const notice = document.getElementById("notice");
  const term = new Terminal({
    fontFamily: 'ui-monospace, "DejaVu Sans Mono", "Liberation Mono", monospace',
    fontSize: 15,
    cursorBlink: false,
    scrollback: 0,
  });
  const fit = new FitAddon.FitAddon();
  term.loadAddon(fit);
  term.open(document.getElementById("terminal"));
  fit.fit();
  window.workbenchTerminal = term; // read by the browser test through the page's buffer
  const encoder = new TextEncoder();
  let socket = null;
  let ended = false;

  function show(message) {
    notice.textContent = message;
    notice.hidden = !message;
  }

  function sendSize() {
    if (socket && socket.readyState === WebSocket.OPEN) {
      socket.send(JSON.stringify({ type: "resize", cols: term.cols, rows: term.rows }));
    }
  }

  function connect() {
    const scheme = location.protocol === "https:" ? "wss:" : "ws:";
    const url = `${scheme}//${location.host}/ws?cols=${term.cols}&rows=${term.rows}`;
    socket = new WebSocket(url);
    socket.binaryType = "arraybuffer";
    socket.onopen = () => show("");
    socket.onmessage = (event) => {
      if (typeof event.data === "string") {
        const said = JSON.parse(event.data);
        if (said.type === "taken" || said.type === "ended") ended = true;
        show(said.message || "");
      } else {
        term.write(new Uint8Array(event.data));
      }
    };
    socket.onclose = () => {
      if (ended) return;
      show("The connection to the lab server was lost; trying again ...");
      setTimeout(connect, 2000);
    };
  }

  term.onData((data) => {
    if (socket && socket.readyState === WebSocket.OPEN) socket.send(encoder.encode(data));
  });
  term.onBinary((data) => {
    if (socket && socket.readyState === WebSocket.OPEN) {
      socket.send(Uint8Array.from(data, (c) => c.charCodeAt(0)));
    }
  });
  term.onResize(sendSize);
  window.addEventListener("resize", () => fit.fit());
  connect();
  term.focus();

  // the files panel: upload into the workspace, download from it
  const panel = document.getElementById("files");
  const listing = document.getElementById("listing");
  const folderLine = document.getElementById("folder");
  const result = document.getElementById("upload-result");
  let folder = "";

  async function list(path) {
    const reply = await fetch(`/files?folder=${encodeURIComponent(path)}`,
      { credentials: "same-origin" });
    const data = await reply.json();
    if (!reply.ok) { result.textContent = data.error; return; }
    folder = data.folder;
    folderLine.textContent = folder;
    listing.replaceChildren();
    if (folder !== "/") {
      const up = document.createElement("li");
      const link = document.createElement("a");
      link.href = "#"; link.textContent = "..";
      link.onclick = (e) => { e.preventDefault(); list(folder.split("/").slice(0, -1).join("/")); };
      up.append(link); listing.append(up);
    }
    for (const entry of data.entries) {
      const item = document.createElement("li");
      const link = document.createElement("a");
      const path = `${folder === "/" ? "" : folder}/${entry.name}`;
      link.textContent = entry.name + (entry.folder ? "/" : "");
      if (entry.folder) {
        link.href = "#";
        link.onclick = (e) => { e.preventDefault(); list(path); };
      } else {
        link.href = `/files${path.split("/").map(encodeURIComponent).join("/")}`;
        link.download = entry.name;
      }
      item.append(link); listing.append(item);
    }
  }

  document.getElementById("files-button").onclick = () => {
    panel.hidden = !panel.hidden;
    if (!panel.hidden) list(folder);
    else term.focus();
  };
  document.getElementById("upload").onsubmit = async (event) => {
    event.preventDefault();
    const form = new FormData(event.target);
    form.append("folder", folder);
    const reply = await fetch("/files", { method: "POST", body: form,
      credentials: "same-origin", headers: { "X-Workbench-Form": body.dataset.csrf } });
    const data = await reply.json();
    result.textContent = reply.ok ? `Sent: ${data.path}` : data.error;
    list(folder);
  };
})();
