// geoshade serve: the page. Pictures are drawn on the server; this script shows them, sends
// the pointer, wheel and keys, and builds the panel the server describes.
"use strict";
const params = new URLSearchParams(location.search);
// the token leaves the address (and this entry of the history) at once: the page lives under
// its server's own path (<base>), where the browser keeps the server's cookie instead
const home = new URL(".", document.baseURI);
if (params.has("token") || location.pathname !== home.pathname) {
  params.delete("token");
  const q = params.toString();
  history.replaceState(null, "", home.pathname + (q ? "?" + q : "") + location.hash);
}
const $ = (id) => document.getElementById(id);
const img = $("frame");
const state = { frames: 0, stills: 0, last: null, still: null, pick: null, settings: {},
                errors: [], kind: null, name: null, busy: [], ready: false, plots: null,
                version: 0, limits: null, address: null, cells: [], history: null, summary: null,
                notes: [] };
window.geoshade = state;   // read by the browser tests

const wsUrl = new URL("ws", home);
wsUrl.protocol = location.protocol === "https:" ? "wss:" : "ws:";
// connected once every script of the page has run (address.js, panel.js, workbench.js define
// what the messages call): a message never finds a function not yet defined
let ws = null;
const send = (m) => { if (ws !== null && ws.readyState === 1) ws.send(JSON.stringify(m)); };
document.addEventListener("DOMContentLoaded", () => {
  ws = new WebSocket(wsUrl.href);
  ws.binaryType = "blob";
  ws.onmessage = onMessage;
  ws.onclose = (ev) => {
    const why = ev.reason ? ` (${ev.reason})` : "";
    $("error").textContent = `the server closed the connection${why}; reload the page`;
  };
});
let pending = null;      // the message whose data comes next
let shownUrl = null;
let addressError = null; // a view in the address this page cannot show: said once it opens

function fixedSize() {
  const s = params.get("size");
  const m = s && /^(\d+)x(\d+)$/.exec(s);
  return m ? [parseInt(m[1]), parseInt(m[2])] : null;
}

function sendSize() {   // within the sizes the server draws (its hello says them)
  const fixed = fixedSize();
  const a = $("area");
  const [w, h] = fixed || [a.clientWidth, a.clientHeight];
  const lim = state.limits || { min_side: 16, max_side: 4096 };
  const fit = (v) => Math.min(lim.max_side, Math.max(lim.min_side, Math.round(v)));
  send({ t: "resize", w: fit(w), h: fit(h) });
}

function onMessage(ev) {
  if (typeof ev.data !== "string") {
    const m = pending; pending = null;
    if (m && m.type === "frame") showFrame(m, ev.data);
    else if (m && m.type === "download") download(m, ev.data);
    else if (m && m.image) showPlot(m, ev.data);
    return;
  }
  const m = JSON.parse(ev.data);
  if (m.type === "frame" || m.type === "download" || m.image) { pending = m; return; }
  if (m.type === "hello") {
    state.limits = m.limits || null;
    const sel = $("file");
    sel.innerHTML = "";
    for (const f of m.files) sel.add(new Option(f, f));
    // the view of the address (address.js) names the file, its part and its state
    const addr = readAddress();
    const view = addr && addr.view;
    const want = view ? view.file : params.get("open");
    if (addr && addr.error) addressError = addr.error;
    else if (view && !m.files.includes(view.file)) {
      addressError = `the view in the address: ${view.file} is not among this server's files`;
    }
    if (want !== null && m.files.includes(want)) sel.value = want;
    sendSize();
    const fromAddress = view && sel.value === view.file;
    if (sel.value) {
      send({ t: "open", name: sel.value, as: (fromAddress ? view.as : params.get("as")) || null,
             ...(fromAddress && view.state ? { state: view.state } : {}) });
    }
  } else if (m.type === "opened") {
    state.kind = m.kind; state.name = m.name; state.reads = m.reads;
    buildPanel(m.panel); syncPanel(m.settings, m.values); state.settings = m.settings;
    $("plots").innerHTML = ""; state.plots = null; $("note").textContent = "";
    $("error").textContent = ""; $("progress").hidden = true;
    if (addressError) { state.errors.push(addressError); $("error").textContent = addressError; addressError = null; }
    resetBench();
    if (fixedSize() === null) sendSize();
  } else if (m.type === "settings") {   // a change was taken: an error it fixed is gone
    $("error").textContent = "";
    state.settings = m.settings; state.busy = m.busy || []; state.version = m.version;
    syncPanel(m.settings, m.values);
    if (!state.busy.length) $("progress").hidden = true;
  } else if (m.type === "progress" || m.type === "busy") {
    $("progress").hidden = false;
    $("progress-label").textContent = m.label;
    const bar = $("bar");
    if (m.total) { bar.max = m.total; bar.value = m.done; } else bar.removeAttribute("value");
  } else if (m.type === "plots") {   // a core's histogram and porosity profile (SVG)
    $("plots").innerHTML = (m.histogram || "") + (m.porosity || "");
    state.plots = { histogram: m.histogram || null, porosity: m.porosity || null };
  } else if (m.type === "pick") {
    state.pick = m.pick; $("pick").textContent = m.text;
  } else if (m.type === "note") {   // a line of what the server did (a click on the summary plot)
    state.notes.push(m.text); $("note").textContent = m.text;
  } else if (m.type === "cells") {
    showCells(m);
  } else if (m.type === "history" || m.type === "summary") {   // no picture: none shown
    showPlot(m, null);
  } else if (m.type === "error") {
    state.errors.push(m.text); $("error").textContent = m.text; $("progress").hidden = true;
  }
}

function showFrame(meta, blob) {
  const url = URL.createObjectURL(new Blob([blob], { type: meta.mime }));
  const done = () => {
    if (shownUrl && shownUrl !== (state.still && state.still.url)) URL.revokeObjectURL(shownUrl);
    shownUrl = url;
    state.frames += 1; state.last = meta;
    if (meta.still) {
      if (state.still && state.still.url !== url) URL.revokeObjectURL(state.still.url);
      state.still = { meta, url }; state.stills += 1;
    }
    $("readout").textContent = meta.readout;
    if (meta.state && state.name !== null) writeAddress({ file: state.name, as: state.kind, state: meta.state });
    img.dataset.seq = meta.seq; img.dataset.still = meta.still;
    send({ t: "ack" });
  };
  img.onload = done; img.onerror = done;
  img.src = url;
}

function download(meta, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([blob], { type: meta.mime }));
  a.download = meta.name;
  document.body.appendChild(a); a.click(); a.remove();
  state.downloaded = meta.name;
}

// --- pointer, wheel, keys ------------------------------------------------------------------
const BUTTONS = { 0: "left", 1: "middle", 2: "right" };
let down = false, queued = null;
img.addEventListener("contextmenu", (e) => e.preventDefault());
img.addEventListener("pointerdown", (e) => {
  img.setPointerCapture(e.pointerId); img.focus(); down = true;
  send({ t: "pointer", kind: "down", x: e.offsetX, y: e.offsetY, button: BUTTONS[e.button] || "other" });
  e.preventDefault();
});
img.addEventListener("pointermove", (e) => {
  if (!down) return;
  const first = queued === null;
  queued = { x: e.offsetX, y: e.offsetY };
  if (first) requestAnimationFrame(() => {   // at most one move per browser frame
    if (queued !== null) send({ t: "pointer", kind: "move", x: queued.x, y: queued.y });
    queued = null;
  });
});
img.addEventListener("pointerup", (e) => {
  if (!down) return;
  down = false;
  if (queued !== null) { send({ t: "pointer", kind: "move", x: queued.x, y: queued.y }); queued = null; }
  send({ t: "pointer", kind: "up", x: e.offsetX, y: e.offsetY });
});
img.addEventListener("wheel", (e) => {
  e.preventDefault(); send({ t: "wheel", notches: -e.deltaY / 100 });
}, { passive: false });
img.addEventListener("keydown", (e) => {
  if (e.ctrlKey || e.metaKey || e.altKey) return;
  send({ t: "key", key: e.key.length === 1 ? e.key : e.key.toLowerCase() });
  e.preventDefault();
});
if (fixedSize() === null) {
  let timer = null;
  new ResizeObserver(() => { clearTimeout(timer); timer = setTimeout(sendSize, 150); }).observe($("area"));
}

// --- buttons -------------------------------------------------------------------------------
$("file").onchange = () => send({ t: "open", name: $("file").value });
$("screenshot").onclick = () => send({ t: "screenshot" });
$("save-camera").onclick = () => send({ t: "save_camera" });
$("load-camera").onchange = async (e) => {
  const f = e.target.files[0];
  if (f) send({ t: "load_camera", text: await f.text() });
  e.target.value = "";
};
