// geoshade serve: a grid's kept picks (every property of each cell at the shown step), a kept
// cell's history over the steps and the summary plot with its time cursor
// (geoshade.web.workbench draws the plots; this shows them and sends the clicks).
"use strict";
let historyShown = null;   // [cell, name] of the history plot shown
const plotUrls = {};

const cellKey = (c) => c.join(",");
function fmt(v) {
  if (v === null || v === undefined) return "—";
  if (typeof v !== "number") return String(v);
  return Number.isInteger(v) ? String(v) : String(+v.toPrecision(6));
}

function resetBench() {
  historyShown = null;
  showCells({ cells: [], step: null, history_names: [] });
  for (const kind of ["history", "summary"]) showPlot({ type: kind, cell: null }, null);
  sendPlotSize();
}

function sendPlotSize() {   // each plot half the width under the picture, within the limits
  const lim = state.limits || { min_plot: 120, max_plot: 2048 };
  const fit = (v) => Math.min(lim.max_plot, Math.max(lim.min_plot, Math.round(v)));
  const w = $("bench").clientWidth || $("area").clientWidth || 640;
  if (state.name !== null) send({ t: "plot_size", w: fit(w / 2 - 8), h: fit(240) });
}

function showCells(m) {
  state.cells = m.cells; state.cellsStep = m.step;
  const root = $("cells");
  root.innerHTML = "";
  root.hidden = !m.cells.length;
  if (m.cells.length) root.appendChild(el("div", { className: "cells-title",
    textContent: `picked cells${m.step === null ? "" : " at " + stepLabel(m.step)}` }));
  for (const c of m.cells) {
    const box = el("div", { className: "cell" });
    box.dataset.cell = cellKey(c.cell);
    const head = el("div", { className: "cell-head" });
    const hist = el("select", { className: "cell-history",
                                title: "plot a property of this cell over the report steps" });
    hist.add(new Option("history of…", ""));
    for (const n of m.history_names) hist.add(new Option(n, n));
    if (historyShown && cellKey(historyShown[0]) === cellKey(c.cell)) hist.value = historyShown[1];
    hist.onchange = () => send({ t: "history", cell: c.cell, name: hist.value || null });
    const rm = el("button", { type: "button", textContent: "×", className: "cell-remove",
                              title: "forget this cell" });
    rm.onclick = () => send({ t: "unpick", cell: c.cell });
    head.append(el("b", { textContent: c.label }), hist, rm);
    const table = el("table", { className: "cell-table" });
    for (const r of c.rows) {
      const tr = table.insertRow();
      tr.insertCell().textContent = r.name;
      tr.insertCell().textContent = fmt(r.value);
      tr.insertCell().textContent = r.unit || "";
    }
    box.append(head, table);
    root.appendChild(box);
  }
}

function stepLabel(k) {
  const c = controls.step;
  return c && c.spec.labels ? c.spec.labels[k] : `step ${k}`;
}

// a plot under the picture: "history" (a kept cell's property) or "summary" (the vectors with
// the time cursor); no data: none shown
function showPlot(meta, blob) {
  const img = $(meta.type + "-plot");
  if (plotUrls[meta.type]) URL.revokeObjectURL(plotUrls[meta.type]);
  plotUrls[meta.type] = null;
  const shown = { ...meta };
  delete shown.image;
  if (blob === null) {
    img.hidden = true; img.removeAttribute("src");
    state[meta.type] = null;
    if (meta.type === "history") historyShown = null;
  } else {
    const url = plotUrls[meta.type] = URL.createObjectURL(new Blob([blob], { type: "image/png" }));
    img.onload = () => { if (plotUrls[meta.type] === url) state[meta.type] = shown; };
    img.src = url; img.hidden = false;
    if (meta.type === "history") historyShown = [meta.cell, meta.name];
  }
  $("bench").hidden = $("history-plot").hidden && $("summary-plot").hidden;
}

// a click on the summary plot: the server moves the step to the report step nearest the date
$("summary-plot").addEventListener("click", (e) => {
  const p = $("summary-plot");
  const sx = p.naturalWidth / p.clientWidth, sy = p.naturalHeight / p.clientHeight;
  send({ t: "timeline", x: e.offsetX * sx, y: e.offsetY * sy });
});
if (fixedSize() === null) {
  let timer = null;
  new ResizeObserver(() => { clearTimeout(timer); timer = setTimeout(sendPlotSize, 200); }).observe($("bench"));
}
