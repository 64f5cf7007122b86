// Charts in SVG: a frame with axes to draw in, a polyline's points, and the logbook's history
// chart (a line per series).

import { el, svg } from './dom.js';
import { fmt } from './format.js';

function niceTicks(lo, hi, count) {
  if (!(hi > lo)) hi = lo + 1;
  const raw = (hi - lo) / Math.max(1, count);
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 2.5, 5, 10].map((f) => f * mag).find((s) => s >= raw) || 10 * mag;
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) ticks.push(Number(v.toFixed(10)));
  return ticks;
}

// A frame with axes (560 wide unless `opts.width`); returns {root, x(v), y(v), plot} for drawing.
export function frame(container, opts) {
  const W = opts.width || 560;
  const H = opts.height || 220;
  const m = { l: 48, r: 14, t: 12, b: 38 };
  const root = svg('svg', { viewBox: `0 0 ${W} ${H}`, width: '100%', role: 'img', 'aria-label': opts.label, class: 'plot' });
  const pw = W - m.l - m.r;
  const ph = H - m.t - m.b;
  const x = (v) => m.l + ((v - opts.x0) / (opts.x1 - opts.x0 || 1)) * pw;
  const y = (v) => m.t + ph - ((v - opts.y0) / (opts.y1 - opts.y0 || 1)) * ph;
  const axes = svg('g', { class: 'axes' });
  for (const t of niceTicks(opts.y0, opts.y1, 5)) {
    if (t < opts.y0 - 1e-9 || t > opts.y1 + 1e-9) continue;
    axes.append(svg('line', { x1: m.l, x2: W - m.r, y1: y(t), y2: y(t), class: 'grid' }));
    axes.append(svg('text', { x: m.l - 6, y: y(t) + 4, 'text-anchor': 'end' }, opts.yFmt ? opts.yFmt(t) : String(t)));
  }
  for (const t of niceTicks(opts.x0, opts.x1, 6)) {
    if (t < opts.x0 - 1e-9 || t > opts.x1 + 1e-9) continue;
    axes.append(svg('line', { x1: x(t), x2: x(t), y1: m.t + ph, y2: m.t + ph + 4, class: 'tick' }));
    axes.append(svg('text', { x: x(t), y: m.t + ph + 16, 'text-anchor': 'middle' }, opts.xFmt ? opts.xFmt(t) : String(t)));
  }
  axes.append(svg('line', { x1: m.l, x2: W - m.r, y1: m.t + ph, y2: m.t + ph, class: 'axis' }));
  axes.append(svg('line', { x1: m.l, x2: m.l, y1: m.t, y2: m.t + ph, class: 'axis' }));
  axes.append(svg('text', { x: m.l + pw / 2, y: H - 4, 'text-anchor': 'middle', class: 'label' }, opts.xLabel));
  axes.append(svg('text', { x: 12, y: m.t + ph / 2, 'text-anchor': 'middle', class: 'label', transform: `rotate(-90 12 ${m.t + ph / 2})` }, opts.yLabel));
  root.append(axes);
  const plot = svg('g', { class: 'data' });
  root.append(plot);
  container.replaceChildren(root);
  return { root, plot, x, y, m, W, H };
}

export function points(xs, ys, fx, fy) {
  const out = [];
  const n = Math.min(xs.length, ys.length);
  for (let i = 0; i < n; i++) {
    if (Number.isFinite(xs[i]) && Number.isFinite(ys[i])) out.push(`${fx(xs[i]).toFixed(1)},${fy(ys[i]).toFixed(1)}`);
  }
  return out;
}

// A history chart: each series its own line through its points and a dot on each (a line never
// joins two series: two packs are two lines), x the flight's place in the series' own flights
// (1, 2, ...); a legend names the series. A series is coloured by its class, or by `colour`.
export function historyChart(container, label, yLabel, series) {
  const all = series.flatMap((s) => s.values.filter(Number.isFinite));
  const n = Math.max(1, ...series.map((s) => s.values.length));
  if (!all.length) {
    container.replaceChildren(el('p', { class: 'muted' }, [`no ${yLabel.split(' (')[0]} in these flights`]));
    return;
  }
  const lo = Math.min(...all);
  const hi = Math.max(...all);
  const pad = (hi - lo) * 0.1 || Math.abs(hi) * 0.1 || 1;
  const f = frame(container, { label, x0: 1, x1: Math.max(2, n), y0: lo - pad, y1: hi + pad, xLabel: 'flight', yLabel });
  const paint = (e, s, fill) => {
    if (s.colour) e.style[fill ? 'fill' : 'stroke'] = s.colour;
    return e;
  };
  for (const s of series) {
    const xs = s.values.map((_, i) => i + 1);
    f.plot.append(paint(svg('polyline', { points: points(xs, s.values, f.x, f.y).join(' '), class: s.cls }), s, false));
    s.values.forEach((v, i) => {
      if (!Number.isFinite(v)) return;
      const dot = paint(svg('circle', { cx: f.x(i + 1), cy: f.y(v), r: 3, class: s.cls }), s, true);
      dot.append(svg('title', {}, `flight ${i + 1}, ${s.name}: ${fmt(v, 1)}`));
      f.plot.append(dot);
    });
  }
  const legend = svg('g', { class: 'legend history-legend', transform: `translate(${f.m.l + 10}, ${f.m.t + 12})` });
  series.forEach((s, k) => {
    const y = k * 14;
    legend.append(paint(svg('line', { x1: 0, x2: 16, y1: y - 3, y2: y - 3, class: s.cls }), s, false));
    legend.append(svg('text', { x: 20, y: y + 1 }, s.name));
  });
  f.plot.append(legend);
}
