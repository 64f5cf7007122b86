// The mission's charts: the battery over time (with the uncertainty band and the reserve) and
// the endurance against payload of the vehicle's pack.

import { $, state } from './state.js';
import { el, svg } from './dom.js';
import { fmt, pct } from './format.js';
import { api } from './api.js';
import { frame, points } from './chart.js';

export function renderChart(mission, mapAnswer) {
  const container = $('#chart');
  const battery = mapAnswer.battery || { time_s: [], soc: [] };
  const band = mapAnswer.band;
  let tMax = 0;
  for (const t of battery.time_s) tMax = Math.max(tMax, t);
  if (band) for (const t of band.time_s) tMax = Math.max(tMax, t);
  if (typeof mission.duration_s === 'number') tMax = Math.max(tMax, mission.duration_s);
  // minutes for flights over 5 min: the x axis is drawn in the unit it shows
  const unit = tMax > 300 ? 60 : 1;
  const tx = (t) => t / unit;
  // the y axis starts below the lowest value (or the reserve), in steps of 10 %
  let low = 100;
  for (const v of battery.soc) low = Math.min(low, v * 100);
  if (band) for (const v of band.p5) low = Math.min(low, v * 100);
  if (typeof mission.required_reserve_soc === 'number') low = Math.min(low, mission.required_reserve_soc * 100);
  const y0 = Math.max(0, Math.floor((low - 5) / 10) * 10);
  const x1 = tx(tMax || 1);
  const f = frame(container, {
    label: 'Battery over time',
    x0: 0,
    x1,
    y0,
    y1: 100,
    xLabel: unit === 60 ? 'time (min)' : 'time (s)',
    yLabel: 'battery (%)',
    xFmt: (t) => String(Number(t.toFixed(2))),
    yFmt: (v) => fmt(v, 0),
  });
  const scaled = (ts) => ts.map(tx);
  if (typeof mission.required_reserve_soc === 'number') {
    const yr = f.y(mission.required_reserve_soc * 100);
    f.plot.append(svg('line', { x1: f.x(0), x2: f.x(x1), y1: yr, y2: yr, class: 'reserve' }));
    f.plot.append(svg('text', { x: f.x(x1) - 4, y: yr - 4, 'text-anchor': 'end', class: 'reserve-label' }, `required reserve ${pct(mission.required_reserve_soc, 0)} %`));
  }
  if (typeof mission.point_of_no_return_s === 'number') {
    const xp = f.x(tx(mission.point_of_no_return_s));
    f.plot.append(svg('line', { x1: xp, x2: xp, y1: f.y(100), y2: f.y(y0), class: 'pnr-line' }));
    f.plot.append(svg('text', { x: xp + 4, y: f.y(100) + 12, class: 'pnr-label' }, 'point of no return'));
  }
  if (band && band.time_s.length) {
    const bt = scaled(band.time_s);
    const upper = points(bt, band.p95.map((v) => v * 100), f.x, f.y);
    const lower = points(bt, band.p5.map((v) => v * 100), f.x, f.y).reverse();
    f.plot.append(svg('polygon', { points: upper.concat(lower).join(' '), class: 'band' }));
    f.plot.append(svg('polyline', { points: points(bt, band.p50.map((v) => v * 100), f.x, f.y).join(' '), class: 'p50' }));
  }
  f.plot.append(svg('polyline', { points: points(scaled(battery.time_s), battery.soc.map((v) => v * 100), f.x, f.y).join(' '), class: 'soc' }));
  // legend, bottom left
  const legend = svg('g', { class: 'legend', transform: `translate(${f.m.l + 10}, ${f.H - f.m.b - 10})` });
  legend.append(svg('rect', { x: -6, y: -14, width: band ? 215 : 80, height: 20, rx: 3, class: 'legend-bg' }));
  let lx = 0;
  const item = (cls, text, kind) => {
    if (kind === 'rect') legend.append(svg('rect', { x: lx, y: -8, width: 16, height: 10, class: cls }));
    else legend.append(svg('line', { x1: lx, x2: lx + 16, y1: -3, y2: -3, class: cls }));
    legend.append(svg('text', { x: lx + 20, y: 1 }, text));
    lx += 28 + text.length * 6;
  };
  item('soc', 'planned', 'line');
  if (band) {
    item('band', 'p5–p95', 'rect');
    item('p50', 'median', 'line');
  }
  f.plot.append(legend);
}

export async function updateSweep(mission) {
  // The vehicle chosen in the list (a given file may be listed under the name it was given
  // with, its own name being a built-in's), else the answer's.
  const vehicle = $('#vehicle').value || mission.vehicle;
  const battery = mission.battery;
  const key = `${vehicle}|${battery}`;
  if (state.sweepKey === key) return;
  let data = state.sweepCache.get(key);
  if (!data) {
    const veh = state.vehicles.find((v) => v.name === vehicle);
    // max payload of this pack: ask once with a one-row sweep, then sweep 0..max
    const probe = await api(`/api/endurance?vehicle=${encodeURIComponent(vehicle)}&battery=${encodeURIComponent(battery)}&payload_sweep=0:0:1`);
    const b = (probe.batteries || []).find((x) => x.name === battery) || (probe.batteries || [])[0];
    const max = b && typeof b.max_payload_kg === 'number' ? b.max_payload_kg : 0;
    if (max > 0) {
      const step = max / 20;
      data = await api(`/api/endurance?vehicle=${encodeURIComponent(vehicle)}&battery=${encodeURIComponent(battery)}&payload_sweep=0:${max}:${step}`);
    } else {
      data = probe;
    }
    data.__max = max;
    data.__vehicle = veh ? veh.name : vehicle;
    state.sweepCache.set(key, data);
  }
  state.sweepKey = key;
  renderSweep(data, vehicle, battery);
}

function renderSweep(data, vehicle, battery) {
  $('#sweep-title').textContent = `${vehicle} · ${battery}`;
  const container = $('#sweep');
  const rows = (data.rows || []).filter((r) => r.battery === battery || !r.battery);
  if (!rows.length) {
    container.replaceChildren(el('p', { class: 'muted', text: 'No payload sweep for this pack.' }));
    return;
  }
  const px = rows.map((r) => r.payload_kg);
  const hover = rows.map((r) => r.hover_endurance_s / 60);
  const best = rows.map((r) => r.max_endurance_s / 60);
  const yMax = Math.max(...hover.filter(Number.isFinite), ...best.filter(Number.isFinite), 1);
  const xMax = Math.max(...px, data.__max || 0, 0.1);
  const f = frame(container, {
    label: 'Endurance against payload',
    height: 200,
    x0: 0,
    x1: xMax,
    y0: 0,
    y1: Math.ceil(yMax / 5) * 5,
    xLabel: 'payload (kg)',
    yLabel: 'endurance (min)',
    xFmt: (v) => String(Number(v.toFixed(2))),
    yFmt: (v) => fmt(v, 0),
  });
  f.plot.append(svg('polyline', { points: points(px, best, f.x, f.y).join(' '), class: 'sweep-max' }));
  f.plot.append(svg('polyline', { points: points(px, hover, f.x, f.y).join(' '), class: 'sweep-hover' }));
  const legend = svg('g', { class: 'legend', transform: `translate(${f.W - f.m.r - 210}, ${f.m.t + 12})` });
  legend.append(svg('line', { x1: 0, x2: 16, y1: -3, y2: -3, class: 'sweep-max' }));
  legend.append(svg('text', { x: 20, y: 1 }, 'max endurance'));
  legend.append(svg('line', { x1: 110, x2: 126, y1: -3, y2: -3, class: 'sweep-hover' }));
  legend.append(svg('text', { x: 130, y: 1 }, 'hover'));
  f.plot.append(legend);
  // the current payload
  const payload = state.plan && state.plan.mission && state.plan.mission.payload_kg;
  if (typeof payload === 'number' && payload <= xMax) {
    const xp = f.x(payload);
    f.plot.append(svg('line', { x1: xp, x2: xp, y1: f.y(0), y2: f.m.t, class: 'payload-line' }));
  }
}
