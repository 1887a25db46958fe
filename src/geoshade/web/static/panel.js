// geoshade serve: the panel, built from the control specs the server sends (geoshade.viewer.
// controls): each control *type* rendered once here, for every part.
"use strict";
// --- panel ---------------------------------------------------------------------------------
const controls = {};
const label = (v) => v === null ? "(none)" : v === true ? "yes" : v === false ? "no" : String(v);
const set = (name, value) => send({ t: "set", values: { [name]: value } });
const el = (tag, props) => Object.assign(document.createElement(tag), props || {});

const PLAY_MS = 300;
// control types laid out as blocks (several inputs each), not in one label
const BLOCKS = ["materials", "section", "button", "ijk", "ranges", "vectors"];
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
  const wrap = document.createElement(BLOCKS.includes(c.type) ? "div" : "label");
  const target = typeof c.sets === "string" ? c.sets : c.name;   // the option it sets
  if (c.type !== "button") wrap.append(c.label + " ");
  let get, put;
  if (c.type in WORKBENCH) {   // I/J/K and value ranges, summary vectors (cuts.js)
    [get, put] = WORKBENCH[c.type](c, wrap, (v) => set(target, v));
  } else if (c.type === "button") {
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
  } else {   // a control type this page does not know: said, never a broken panel
    wrap.appendChild(el("span", { className: "hint", textContent: "(not shown in the browser)" }));
    put = () => {};
  }
  if (get) get.id = "ctl-" + c.name;
  controls[c.name] = { spec: c, put };
  return wrap;
}

// settings: the View's options; values: what each control shows (geoshade.viewer.values),
// the I/J/K, range and vector controls' own form
function syncPanel(settings, values) {
  const color = settings.color && typeof settings.color === "object" ? settings.color : {};
  const alias = { colormap: "colormap", color_range: "range", log: "log", reverse: "reverse",
                  categorical: "categorical" };
  for (const [name, c] of Object.entries(controls)) {
    if (c.spec.type === "materials") { c.put(settings); continue; }
    if (c.spec.type in WORKBENCH) { if (values && name in values) c.put(values[name]); continue; }
    if (c.spec.type === "button" || (c.spec.sets && c.spec.type !== "section")) continue;
    const key = c.spec.type === "section" ? "plane" : name;
    let v = key in settings ? settings[key] : (alias[key] in color ? color[alias[key]] : undefined);
    if (v === undefined) continue;
    if (["log", "categorical", "occlusion"].includes(name) && v === null) v = "auto";
    if (name === "wells") v = Array.isArray(v) ? v.length > 0 : !!v;
    c.put(v);
  }
}
