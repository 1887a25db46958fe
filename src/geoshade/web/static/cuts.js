// geoshade serve: the workbench's control types (geoshade.viewer.controls): I/J/K range
// sliders ("ijk", the slice option), per-property min/max sliders ("ranges", next to the typed
// filter) and the summary vectors ("vectors"). Each maker builds its inputs into `wrap`, calls
// `send(value)` with the value the server checks (geoshade.web.messages) and returns
// [element, put(value)] (put shows a value without sending it back).
"use strict";
const SLIDER_STEPS = 1000;   // a range slider's positions between a property's min and max

function numText(v) {
  return Math.abs(v) >= 1e5 || (v !== 0 && Math.abs(v) < 1e-3) ? v.toExponential(3) : String(+v.toPrecision(5));
}

// two sliders (from, to) in one row; change(lo, hi) after either moved, the other kept apart
function twoSliders(min, max, step, shownAs, change) {
  const lo = el("input", { type: "range", min, max, step, value: min, className: "lo" });
  const hi = el("input", { type: "range", min, max, step, value: max, className: "hi" });
  const text = el("span", { className: "range-text" });
  const show = () => { text.textContent = shownAs(+lo.value, +hi.value); };
  const gap = step === "any" ? 0 : +step;
  lo.oninput = () => { if (+lo.value > +hi.value - gap) lo.value = +hi.value - gap; show(); };
  hi.oninput = () => { if (+hi.value < +lo.value + gap) hi.value = +lo.value + gap; show(); };
  lo.onchange = hi.onchange = () => change(+lo.value, +hi.value);
  show();
  return { lo, hi, text, show };
}

const WORKBENCH = {
  // [[i0, i1], [j0, j1], [k0, k1]], 0-based and end exclusive; shown 1-based as ECLIPSE counts
  ijk(c, wrap, send) {
    const rows = [];
    const box = el("div", { className: "ijk" });
    const changed = () => send(rows.map((r) => [+r.lo.value, +r.hi.value]));
    c.dims.forEach((n, a) => {
      const axis = "IJK"[a];
      const r = twoSliders(0, n, 1, (lo, hi) => `${lo + 1}–${hi}`, changed);
      r.lo.max = n - 1; r.hi.min = 1;
      r.lo.id = `ctl-slice-${axis.toLowerCase()}0`; r.hi.id = `ctl-slice-${axis.toLowerCase()}1`;
      const row = el("div", { className: "range-row" });
      row.append(el("span", { className: "range-name", textContent: axis }), r.lo, r.hi, r.text);
      box.appendChild(row);
      rows.push(r);
    });
    wrap.appendChild(box);
    const put = (v) => rows.forEach((r, a) => {
      const [lo, hi] = Array.isArray(v) && Array.isArray(v[a]) ? v[a] : [0, c.dims[a]];
      r.lo.value = lo; r.hi.value = hi; r.show();
    });
    return [box, put];
  },
  // {NAME: [lo, hi]} of the narrowed properties (a slider at its end: not narrowed)
  ranges(c, wrap, send) {
    const rows = [];
    const details = el("details", { className: "ranges" });
    const head = el("summary");
    details.appendChild(head);
    const value = (r, p) => (p <= 0 ? r.min : p >= SLIDER_STEPS ? r.max : r.min + (r.max - r.min) * p / SLIDER_STEPS);
    const pos = (r, v, end) => (r.max > r.min ? Math.round(SLIDER_STEPS * (v - r.min) / (r.max - r.min)) : end);
    const count = () => rows.filter((r) => +r.lo.value > 0 || +r.hi.value < SLIDER_STEPS).length;
    const title = () => { head.textContent = `${count()} of ${rows.length} narrowed`; };
    const changed = () => {
      const out = {};
      for (const r of rows) {
        if (+r.lo.value > 0 || +r.hi.value < SLIDER_STEPS) out[r.name] = [value(r, +r.lo.value), value(r, +r.hi.value)];
      }
      title(); send(out);
    };
    for (const [name, min, max] of c.items) {
      const r = { name, min, max };
      Object.assign(r, twoSliders(0, SLIDER_STEPS, 1, (lo, hi) => `${numText(value(r, lo))} – ${numText(value(r, hi))}`, changed));
      r.lo.id = `ctl-range-${name}-lo`; r.hi.id = `ctl-range-${name}-hi`;
      r.lo.disabled = r.hi.disabled = !(max > min);   // one value everywhere: nothing to narrow
      const row = el("div", { className: "range-row" });
      row.dataset.name = name;
      row.append(el("span", { className: "range-name", textContent: name, title: name }), r.lo, r.hi, r.text);
      details.appendChild(row);
      rows.push(r);
    }
    title();
    wrap.appendChild(details);
    const put = (v) => {
      const given = v && typeof v === "object" ? v : {};
      for (const r of rows) {
        const [lo, hi] = Array.isArray(given[r.name]) ? given[r.name] : [r.min, r.max];
        r.lo.value = pos(r, lo, 0); r.hi.value = pos(r, hi, SLIDER_STEPS); r.show();
      }
      if (count()) details.open = true;
      title();
    };
    return [details, put];
  },
  // names or wildcards, separated by commas or spaces (FOPR, WBHP:PROD, WOPR:*); empty: none
  vectors(c, wrap, send) {
    const list = el("datalist", { id: "summary-vectors" });
    for (const k of c.choices) list.appendChild(el("option", { value: k }));
    const t = el("input", { type: "text", placeholder: "FOPR, WBHP:*", autocomplete: "off" });
    t.setAttribute("list", list.id);
    t.title = `${c.choices.length} vectors; names or wildcards, comma separated: drawn under the picture`;
    t.onchange = () => {
      const names = t.value.split(/[\s,]+/).filter((x) => x);
      send(names.length ? names : null);
    };
    wrap.append(t, list);
    return [t, (v) => { t.value = Array.isArray(v) ? v.join(", ") : ""; }];
  },
};
