// The route's profile over the ground, under the map (with `aloft serve --terrain DIR`): the
// vehicle's altitude and the ground under it (filled) along the distance flown from home, the
// least clearance of the answer marked and labelled. Drawn from the map answer's `profile`
// (the engine's, src/engine/front_door/maps/profile.rs); hidden when the answer has none.

import { $, state } from './state.js';
import { svg } from './dom.js';
import { fmt } from './format.js';
import { frame, points } from './chart.js';

// The profile of a map answer when it is one to draw: three series of one length, at least two
// points, every value a finite number.
function usable(profile) {
  if (!profile || typeof profile !== 'object') return null;
  const { distance_m: d, altitude_m: a, ground_m: g } = profile;
  if (![d, a, g].every(Array.isArray)) return null;
  if (d.length < 2 || a.length !== d.length || g.length !== d.length) return null;
  if (![d, a, g].every((s) => s.every(Number.isFinite))) return null;
  return profile;
}

// The value of `ys` at distance `x` (distances never decreasing), linear between the points
// around it.
function at(xs, ys, x) {
  let k = 0;
  while (k + 1 < xs.length && xs[k + 1] < x) k++;
  if (k + 1 >= xs.length) return ys[ys.length - 1];
  const span = xs[k + 1] - xs[k];
  if (!(span > 0) || x <= xs[k]) return ys[k];
  return ys[k] + ((x - xs[k]) / span) * (ys[k + 1] - ys[k]);
}

// The label of a least clearance, as the page shows it.
export function leastLabel(least) {
  return `least clearance ${fmt(least.clearance_m, 1)} m, segment ${fmt(least.segment, 0)}`;
}

function showPanel(on) {
  const panel = $('#profile-panel');
  if (panel.hidden === !on) return;
  panel.hidden = !on;
  // The map gave the chart its height (or takes it back).
  if (state.map) state.map.invalidateSize();
}

export function clearProfile() {
  const container = $('#profile');
  container.replaceChildren();
  delete container.dataset.points;
  delete container.dataset.leastM;
  showPanel(false);
}

export function renderProfile(mapAnswer) {
  const profile = usable(mapAnswer && mapAnswer.profile);
  if (!profile) {
    clearProfile();
    return;
  }
  showPanel(true);
  const container = $('#profile');
  const { distance_m: d, altitude_m: a, ground_m: g } = profile;
  const xMax = Math.max(...d, 1);
  // kilometres for a route over 5 km: the x axis is drawn in the unit it shows
  const unit = xMax > 5000 ? 1000 : 1;
  const xs = d.map((v) => v / unit);
  const lo = Math.min(...g, ...a);
  const hi = Math.max(...g, ...a);
  const pad = Math.max((hi - lo) * 0.08, 5);
  const y0 = Math.floor((lo - pad) / 10) * 10;
  // Headroom above the route for the least clearance's label.
  const y1 = Math.ceil((hi + 3 * pad) / 10) * 10;
  const f = frame(container, {
    label: 'Route profile over the ground',
    width: 800,
    height: 200,
    x0: 0,
    x1: xMax / unit,
    y0,
    y1,
    xLabel: unit === 1000 ? 'distance from home (km)' : 'distance from home (m)',
    yLabel: 'altitude AMSL (m)',
    xFmt: (v) => String(Number(v.toFixed(2))),
    yFmt: (v) => fmt(v, 0),
  });
  // The ground, filled down to the bottom of the frame.
  const ground = points(xs, g, f.x, f.y);
  const base = [`${f.x(xs[xs.length - 1]).toFixed(1)},${f.y(y0).toFixed(1)}`, `${f.x(xs[0]).toFixed(1)},${f.y(y0).toFixed(1)}`];
  f.plot.append(svg('polygon', { points: ground.concat(base).join(' '), class: 'ground' }));
  f.plot.append(svg('polyline', { points: ground.join(' '), class: 'ground-line' }));
  f.plot.append(svg('polyline', { points: points(xs, a, f.x, f.y).join(' '), class: 'route-altitude' }));
  container.dataset.points = String(d.length);
  drawLeast(f, profile, unit);
  legend(f);
}

// The least clearance: the gap between the ground and the route marked, and labelled.
function drawLeast(f, profile, unit) {
  const least = profile.least;
  const container = $('#profile');
  if (!least || !Number.isFinite(least.distance_m) || !Number.isFinite(least.clearance_m)) {
    delete container.dataset.leastM;
    return;
  }
  container.dataset.leastM = String(least.clearance_m);
  const { distance_m: d, ground_m: g } = profile;
  const x = f.x(least.distance_m / unit);
  const groundY = f.y(at(d, g, least.distance_m));
  const routeY = f.y(at(d, g, least.distance_m) + least.clearance_m);
  const mark = svg('g', { class: 'least' });
  mark.append(svg('line', { x1: x, x2: x, y1: groundY, y2: routeY, class: 'least-gap' }));
  const dot = svg('circle', { cx: x, cy: routeY, r: 4, class: 'least-dot' });
  const text = leastLabel(least);
  dot.append(svg('title', {}, text));
  mark.append(dot);
  // Above the point, kept inside the frame: from its left on the left half, else to its right.
  const left = x < f.m.l + (f.W - f.m.l - f.m.r) / 2;
  const labelY = Math.max(f.m.t + 10, routeY - 10);
  mark.append(svg('text', { x: left ? x + 6 : x - 6, y: labelY, 'text-anchor': left ? 'start' : 'end', class: 'least-label' }, text));
  f.plot.append(mark);
}

function legend(f) {
  const box = svg('g', { class: 'legend', transform: `translate(${f.W - f.m.r - 150}, ${f.H - f.m.b - 10})` });
  box.append(svg('rect', { x: -6, y: -14, width: 150, height: 20, rx: 3, class: 'legend-bg' }));
  box.append(svg('line', { x1: 0, x2: 16, y1: -3, y2: -3, class: 'route-altitude' }));
  box.append(svg('text', { x: 20, y: 1 }, 'route'));
  box.append(svg('rect', { x: 66, y: -8, width: 16, height: 10, class: 'ground' }));
  box.append(svg('text', { x: 86, y: 1 }, 'ground'));
  f.plot.append(box);
}
