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
                version: 0, limits: null };
window.geoshade = state;   // read by the browser tests

const wsUrl = new URL("ws", home);
wsUrl.protocol = location.protocol === "https:" ? "wss:" : "ws:";
const ws = new WebSocket(wsUrl.href);
ws.binaryType = "blob";
const send = (m) => { if (ws.readyState === 1) ws.send(JSON.stringify(m)); };
let pending = null;      // the message whose data comes next
let shownUrl = null;

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

ws.onmessage = (ev) => {
  if (typeof ev.data !== "string") {
    const m = pending; pending = null;
    if (m && m.type === "frame") showFrame(m, ev.data);
    else if (m && m.type === "download") download(m, ev.data);
    return;
  }
  const m = JSON.parse(ev.data);
  if (m.type === "frame" || m.type === "download") { pending = m; return; }
  if (m.type === "hello") {
    state.limits = m.limits || null;
    const sel = $("file");
    sel.innerHTML = "";
    for (const f of m.files) sel.add(new Option(f, f));
    const want = params.get("open");
    if (want !== null) sel.value = want;
    sendSize();
    if (sel.value) send({ t: "open", name: sel.value, as: params.get("as") || null });
  } else if (m.type === "opened") {
    state.kind = m.kind; state.name = m.name; state.reads = m.reads;
    buildPanel(m.panel); syncPanel(m.settings); state.settings = m.settings;
    $("plots").innerHTML = ""; state.plots = null;
    $("error").textContent = ""; $("progress").hidden = true;
    if (fixedSize() === null) sendSize();
  } else if (m.type === "settings") {   // a change was taken: an error it fixed is gone
    $("error").textContent = "";
    state.settings = m.settings; state.busy = m.busy || []; state.version = m.version;
    syncPanel(m.settings);
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
  } else if (m.type === "error") {
    state.errors.push(m.text); $("error").textContent = m.text; $("progress").hidden = true;
  }
};
ws.onclose = (ev) => {
  const why = ev.reason ? ` (${ev.reason})` : "";
  $("error").textContent = `the server closed the connection${why}; reload the page`;
};

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

// --- panel ---------------------------------------------------------------------------------
const controls = {};
const label = (v) => v === null ? "(none)" : v === true ? "yes" : v === false ? "no" : String(v);
const set = (name, value) => send({ t: "set", values: { [name]: value } });
const el = (tag, props) => Object.assign(document.createElement(tag), props || {});

const PLAY_MS = 300;
let playing = null, stopPlaying = () => {};

function buildPanel(groups) {
  stopPlaying();
  const root = $("panel");
  root.innerHTML = "";
  for (const k in controls) delete controls[k];
  for (const g of groups) {
    const fs = document.createElement("fieldset");
    fs.appendChild(el("legend", { textContent: g.group }));
    for (const c of g.controls) fs.appendChild(makeControl(c));
    root.appendChild(fs);
  }
}

function makeControl(c) {
  const wrap = document.createElement(["materials", "section", "button"].includes(c.type) ? "div" : "label");
  const target = typeof c.sets === "string" ? c.sets : c.name;   // the option it sets
  if (c.type !== "button") wrap.append(c.label + " ");
  let get, put;
  if (c.type === "button") {
    const b = el("button", { textContent: c.label, type: "button" });
    b.onclick = () => set(target, c.value);
    get = b; put = () => {};
    wrap.appendChild(b);
  } else if (c.type === "materials") {   // one row per material: visible, opacity (0..100 %)
    const rows = [];
    const changed = () => {
      const hide = [], opacity = {};
      for (const r of rows) {
        if (!r.box.checked) hide.push(r.code);
        if (+r.range.value < 100) opacity[r.code] = +r.range.value / 100;
      }
      send({ t: "set", values: { hide, opacity } });
    };
    const list = el("div", { className: "materials" });
    for (const [code, name, colour] of c.items) {
      const row = el("label", { className: "material" });
      const box = el("input", { type: "checkbox", checked: true, id: `ctl-material-${code}` });
      const range = el("input", { type: "range", min: 0, max: 100, value: 100, id: `ctl-opacity-${code}` });
      const swatch = el("span", { className: "swatch" });
      swatch.style.background = colour;
      box.onchange = changed; range.onchange = changed;
      row.append(box, swatch, ` ${code} ${name} `, range);
      list.appendChild(row);
      rows.push({ code, box, range });
    }
    get = list;
    put = (settings) => {
      const hidden = new Set(settings.hide || []), op = settings.opacity || {};
      for (const r of rows) {
        r.box.checked = !hidden.has(r.code);
        r.range.value = Math.round(100 * (r.code in op ? op[r.code] : 1));
      }
    };
    wrap.appendChild(list);
  } else if (c.type === "section") {   // a cut across x, y or z at a fraction of the model
    const on = el("input", { type: "checkbox", id: "ctl-section" });
    const axis = el("select", { id: "ctl-section-axis" });
    for (const a of c.axes) axis.add(new Option(a, a));
    const pos = el("input", { type: "range", min: 1, max: 99, value: 50, id: "ctl-section-pos" });
    const flip = el("input", { type: "checkbox", id: "ctl-section-flip" });
    const changed = () => set("plane", on.checked ? [axis.value, +pos.value / 100, flip.checked] : null);
    for (const x of [on, axis, pos, flip]) x.onchange = changed;
    wrap.append(on, " cut ", axis, pos, flip, " flip");
    get = on;
    put = (v) => {
      on.checked = Array.isArray(v);
      if (Array.isArray(v)) { axis.value = v[0]; pos.value = Math.round(100 * v[1]); flip.checked = !!v[2]; }
    };
  } else if (c.type === "select") {
    const s = document.createElement("select");
    for (const v of c.choices) s.add(new Option(label(v), JSON.stringify(v)));
    s.onchange = () => set(target, JSON.parse(s.value));
    get = s; put = (v) => {
      const j = JSON.stringify(v === undefined ? null : v);
      if (![...s.options].some((o) => o.value === j)) s.add(new Option(label(v), j));
      s.value = j;
    };
    wrap.appendChild(s);
  } else if (c.type === "check") {
    const b = document.createElement("input"); b.type = "checkbox";
    b.onchange = () => set(target, b.checked);
    get = b; put = (v) => { b.checked = !!v && !(Array.isArray(v) && v.length === 0); };
    wrap.prepend(b);
  } else if (c.type === "number") {
    const n = document.createElement("input"); n.type = "number"; n.step = c.step || "any";
    if (c.min !== undefined) n.min = c.min;
    if (c.max !== undefined) n.max = c.max;
    n.onchange = () => { if (n.value !== "") set(target, parseFloat(n.value)); };
    get = n; put = (v) => { if (typeof v === "number") n.value = +v.toPrecision(6); };
    wrap.appendChild(n);
  } else if (c.type === "text") {
    const t = document.createElement("input"); t.type = "text"; t.placeholder = c.placeholder || "";
    t.onchange = () => set(target, t.value.trim());
    get = t; put = (v) => { t.value = v === null || v === undefined ? "" : String(v); };
    wrap.appendChild(t);
  } else if (c.type === "pair" || c.type === "ints") {
    const n = c.type === "pair" ? 2 : c.n;
    const inputs = [];
    for (let i = 0; i < n; i++) {
      const x = document.createElement("input"); x.type = "number"; x.step = "any";
      if (c.type === "ints") { x.className = "int"; x.step = "1"; }
      x.placeholder = c.placeholder || "";
      x.dataset.index = i;
      x.onchange = () => {
        const vals = inputs.map((y) => y.value);
        if (vals.every((v) => v === "")) set(target, null);
        else if (vals.every((v) => v !== "")) set(target, vals.map(Number));
      };
      inputs.push(x); wrap.appendChild(x);
    }
    get = inputs[0];
    put = (v) => inputs.forEach((x, i) => {
      x.value = Array.isArray(v) && typeof v[i] === "number" ? +v[i].toPrecision(6) : "";
    });
  } else if (c.type === "step") {
    const r = document.createElement("input"); r.type = "range"; r.min = c.min; r.max = c.max;
    const shown = document.createElement("div");
    r.oninput = () => { shown.textContent = c.labels[r.value]; };
    r.onchange = () => set(target, parseInt(r.value));
    get = r; put = (v) => { if (typeof v === "number") { r.value = v; shown.textContent = c.labels[v]; } };
    // play: the next step once the page shows the last one (drawn with the settings it asked
    // for, no long change running), at most every PLAY_MS; wraps round, as the desktop viewer
    const play = el("button", { type: "button", textContent: "▶ play", id: "ctl-step-play" });
    let sent = null;
    play.onclick = () => {
      if (playing !== null) { stopPlaying(); return; }
      play.textContent = "⏸ pause"; sent = null;
      playing = setInterval(() => {
        const shownNow = state.last && (state.last.version || 0) >= state.version;
        if (state.busy.length || !shownNow || (sent !== null && state.version <= sent)) return;
        const k = (parseInt(r.value) + 1) % (c.max + 1);
        r.value = k; shown.textContent = c.labels[k];
        sent = state.version; set(target, k);
      }, PLAY_MS);
      stopPlaying = () => { clearInterval(playing); playing = null; play.textContent = "▶ play"; };
    };
    wrap.appendChild(r); wrap.appendChild(play); wrap.appendChild(shown);
  }
  if (get) get.id = "ctl-" + c.name;
  controls[c.name] = { spec: c, put };
  return wrap;
}

function syncPanel(settings) {
  const color = settings.color && typeof settings.color === "object" ? settings.color : {};
  const alias = { colormap: "colormap", color_range: "range", log: "log", reverse: "reverse",
                  categorical: "categorical" };
  for (const [name, c] of Object.entries(controls)) {
    if (c.spec.type === "materials") { c.put(settings); continue; }
    if (c.spec.type === "button" || (c.spec.sets && c.spec.type !== "section")) continue;
    const key = c.spec.type === "section" ? "plane" : name;
    let v = key in settings ? settings[key] : (alias[key] in color ? color[alias[key]] : undefined);
    if (v === undefined) continue;
    if (["log", "categorical", "occlusion"].includes(name) && v === null) v = "auto";
    if (name === "wells") v = Array.isArray(v) ? v.length > 0 : !!v;
    c.put(v);
  }
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
