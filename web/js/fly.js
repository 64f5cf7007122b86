// The plan to fly: the files to upload, one per battery (`/api/plan`), their figures against the
// mission as given, what changed, the downloads, and each sortie on the map in its colour.

import { $, options, state } from './state.js';
import { el, tipNode } from './dom.js';
import { fmt, mmss, pct, safeFileName, sortieColour, uniqueNames } from './format.js';
import { api, clearError, fetchText, settle, showError } from './api.js';
import { zipStored } from './zip.js';
import { replanPending } from './mission.js';
import { clearFly } from './fly-clear.js';

// The plan's options: the page's controls (not the mission's samples: a plan draws its own
// scenarios) and the panel's own.
function flyOptions() {
  const q = options();
  q.delete('samples');
  const add = (key, id) => {
    const v = $(id).value.trim();
    if (v !== '') q.set(key, v);
  };
  add('confidence', '#fly-confidence');
  add('speeds', '#fly-speeds');
  add('overlap_m', '#fly-overlap');
  add('max_speed', '#fly-max-speed');
  return q;
}

export async function planToFly() {
  const entry = state.current;
  if (!entry || entry.key === 'none') {
    showError('Plan to fly: no mission selected');
    return;
  }
  // The values just typed: their re-plan, still waiting, runs now (it forgets any plan shown),
  // and this plan is asked for after it, with the same values (read below, at the press).
  replanPending();
  clearFly('planning…');
  const seq = state.flySeq;
  const planSeq = state.planSeq;
  const box = $('#fly');
  box.dataset.state = 'loading';
  $('#plan-fly').disabled = true;
  let ok = false;
  try {
    if (entry.text === null) entry.text = await fetchText(`/api/files/${entry.index}`);
    const q = flyOptions();
    if (entry.name) q.set('file', entry.name);
    const plan = await api(`/api/plan?${q.toString()}`, { method: 'POST', body: entry.text, headers: { 'Content-Type': 'text/plain' } });
    if (seq !== state.flySeq || planSeq !== state.planSeq) return;
    renderFly(plan);
    clearError();
    ok = true;
  } catch (e) {
    if (seq !== state.flySeq) return;
    clearFly('No plan.');
    box.dataset.state = 'error';
    showError(`Plan to fly: ${e instanceof Error ? e.message : String(e)}`);
  } finally {
    $('#plan-fly').disabled = false;
    // Ready unless an error is shown (this plan's, or a re-plan's that replaced it).
    settle(ok || $('#error').hidden);
  }
}

function renderFly(plan) {
  const box = $('#fly');
  if (plan.feasible === false) {
    box.dataset.state = 'infeasible';
    box.replaceChildren(el('p', { class: 'bad', text: `No plan keeps the reserve: ${plan.reason}` }));
    return;
  }
  $('#fly-title').textContent = `${plan.batteries} ${plan.batteries === 1 ? 'battery' : 'batteries'}`;
  const children = [flyFigures(plan), flyConfidence(plan), flySorties(plan)].filter(Boolean);
  const changes = flyChanges(plan);
  if (changes) children.push(changes);
  children.push(flyDownloads(plan));
  box.replaceChildren(...children);
  drawFly(plan);
  box.dataset.batteries = String(plan.batteries);
  box.dataset.state = 'ready';
}

// As given against the plan: batteries, flight time, energy.
function flyFigures(plan) {
  const head = el('tr', {}, [['', ''], ['Batteries', ''], ['Flight time', 'min:s'], ['Energy', 'Wh']].map(headCell));
  const row = (label, f, cls) =>
    el('tr', { class: cls }, [
      el('th', { text: label }),
      el('td', { class: 'n', text: f ? String(f.batteries) : '–' }),
      el('td', { class: 'n', text: f ? mmss(f.duration_s) : '–' }),
      el('td', { class: 'n', text: f ? fmt(f.energy_wh, 1) : '–' }),
    ]);
  const given = plan.as_given;
  const rows = [row('as given', given, 'fly-given'), row('plan', plan, 'fly-plan')];
  if (!given) rows[0].title = 'the mission as given cannot be split at whole items';
  return el('table', { class: 'fly fly-figures' }, [el('thead', {}, [head]), el('tbody', {}, rows)]);
}

// The confidence the sorties were cut at, and the scenarios it was judged in.
function flyConfidence(plan) {
  if (typeof plan.confidence !== 'number' || !plan.scenarios) return null;
  const sc = plan.scenarios;
  const sp = sc.spreads || {};
  const spreads = [
    `wind ${fmt(sp.wind_speed_sd_mps, 1)} m/s and ${fmt(sp.wind_from_sd_deg, 0)}°`,
    `pack capacity ${fmt(sp.capacity_sd_percent, 0)} %`,
    `power ${fmt(sp.power_sd_percent, 0)} %`,
    `payload ${fmt(sp.payload_sd_kg, 1)} kg`,
  ];
  const share = Number((100 * plan.confidence).toFixed(1));
  const text = `Sorties cut to land with the reserve in ${share} % of ${sc.samples} scenarios of the day (1 sd: ${spreads.join(', ')}).`;
  return el('p', { class: 'fly-confidence', 'data-confidence': String(plan.confidence), text });
}

// One row per sortie, in its map colour: its file's items as QGroundControl numbers them, the
// mission's items it flies, its landing (the forecast's, and p5–p95 over the day's scenarios).
function flySorties(plan) {
  const heads = [
    ['#', ''], ['File items', ''], ['Mission items', ''], ['Energy', 'Wh'], ['Time', 'min:s'],
    ['Landing', 'p5–p95, %'], ['Reserve', 'kept, %'], ['No return', 'min:s'], ['File', ''],
  ];
  const head = el('tr', {}, heads.map(headCell));
  const texts = plan.texts || [];
  const rows = plan.sorties.map((s, k) => {
    let items = s.first_item !== undefined ? `${s.first_item}–${s.last_item}` : '–';
    const inside = typeof s.ends_inside_leg_fraction === 'number';
    if (inside) items += '*';
    const own = texts[k] ? fileItemRange(texts[k].file, texts[k].text) : null;
    const band = s.landing_soc;
    const tr = el('tr', {
      'data-sortie': String(k + 1),
      'data-file': s.file,
      'data-energy-wh': String(s.energy_wh),
      'data-duration-s': String(s.duration_s),
      'data-end-soc': String(s.end_soc),
      'data-p-reserve': typeof s.p_reserve === 'number' ? String(s.p_reserve) : undefined,
    }, [
      el('td', { class: 'n' }, [el('span', { class: 'swatch', style: `background:${sortieColour(k)}` }), String(k + 1)]),
      el('td', { class: 'n file-items', text: own ? `${own[0]}–${own[1]}` : '–' }),
      el('td', { class: 'n mission-items', text: items }),
      el('td', { class: 'n', text: fmt(s.energy_wh, 1) }),
      el('td', { class: 'n', text: mmss(s.duration_s) }),
      el('td', { class: 'n band', text: band ? `${pct(band.p5)}–${pct(band.p95)}` : '–' }),
      el('td', { class: 'n p-reserve', text: pct(s.p_reserve) }),
      el('td', { class: 'n', text: typeof s.point_of_no_return_s === 'number' ? mmss(s.point_of_no_return_s) : 'none' }),
      el('td', { class: 'file', text: s.file }),
    ]);
    const tips = [];
    if (own) tips.push(`items ${own[0]}–${own[1]} as QGroundControl lists ${texts[k].file}`);
    if (s.first_item !== undefined) tips.push(`the mission's items ${s.first_item}–${s.last_item}`);
    if (inside) tips.push(`turns home ${fmt(s.ends_inside_leg_fraction * 100, 0)} % of the way along the leg to the mission's item ${s.last_item}`);
    tips.push(`lands with ${pct(s.end_soc)} % in the forecast's wind`);
    if (band) tips.push(`with ${pct(band.p5)}–${pct(band.p95)} % (median ${pct(band.p50)} %) in 90 % of the day's scenarios`);
    if (typeof s.p_reserve === 'number') tips.push(`keeps the reserve in ${pct(s.p_reserve)} % of them`);
    tr.title = tips.join('; ');
    tr.addEventListener('mouseenter', () => lightSortie(k, true));
    tr.addEventListener('mouseleave', () => lightSortie(k, false));
    return tr;
  });
  const key = el('p', {
    class: 'fly-key muted',
    text: 'File items: as QGroundControl lists that file (0 is home); mission items: those of the mission as given; * turns home inside a leg; landing p5–p95: the battery at landing over the day\'s scenarios (the forecast\'s on hover); reserve kept: the share of them landing with the reserve. On the map: each sortie in its colour, the route solid, the way out dashed, the way home dotted; ◆ where a sortie turns home, ■ where the next resumes.',
  });
  return el('div', {}, [el('div', { class: 'table-wrap' }, [el('table', { class: 'fly fly-sorties' }, [el('thead', {}, [head]), el('tbody', {}, rows)])]), key]);
}

// The first and last item numbers of a written file as QGroundControl lists them (its own
// sequence numbers: a `.plan`'s items in order from 1, each of a survey's items counted; a
// `.waypoints` file's rows after home), or null for a file of another kind.
export function fileItemRange(name, text) {
  const file = String(name || '').toLowerCase();
  try {
    if (file.endsWith('.plan')) {
      let count = 0;
      for (const it of JSON.parse(text).mission.items) {
        const inner = it.TransectStyleComplexItem && it.TransectStyleComplexItem.Items;
        count += it.type === 'ComplexItem' && Array.isArray(inner) ? inner.length : 1;
      }
      return count ? [1, count] : null;
    }
    const lines = String(text).split(/\r?\n/).map((l) => l.trim()).filter((l) => l !== '');
    if (!lines.length || !/^QGC WPL/.test(lines[0])) return null;
    const seqs = lines.slice(2).map((l) => Number(l.split(/\s+/)[0]));
    if (!seqs.length || !seqs.every(Number.isInteger)) return null;
    return [seqs[0], seqs[seqs.length - 1]];
  } catch (e) {
    return null;
  }
}

// A header cell: its name, and its unit below it.
function headCell([name, unit]) {
  return el('th', {}, unit ? [name, el('br'), el('span', { class: 'unit', text: `(${unit})` })] : [name]);
}

// What changed from the mission as given.
function flyChanges(plan) {
  const c = plan.changes || {};
  const speeds = c.speeds || [];
  const lines = [];
  if (c.cut_inside_legs) lines.push(el('li', { text: "sorties end inside legs (*), where each pack still lands with the reserve at the plan's confidence" }));
  if (speeds.length) {
    const leg = (s) => (s.item !== undefined ? `item ${s.item}` : `segment ${s.segment}`);
    const from = (s) => (typeof s.from_mps === 'number' ? `${fmt(s.from_mps, 1)} m/s` : 'planning speed');
    const list = el('ul', {}, speeds.map((s) => el('li', { text: `${leg(s)}: ${from(s)} → ${fmt(s.to_mps, 1)} m/s` })));
    const n = speeds.length;
    lines.push(el('li', {}, [el('details', {}, [el('summary', { text: `${n} ${n === 1 ? 'leg' : 'legs'} at the speed of least energy in ${n === 1 ? 'its' : 'their'} wind` }), list])]));
  }
  for (const a of c.angles || []) {
    lines.push(el('li', { text: `survey at item ${a.item} turned to the wind: grid angle ${fmt(a.from_deg, 0)}° → ${fmt(a.to_deg, 0)}°` }));
  }
  for (const note of plan.notes || []) lines.push(el('li', { text: `note: ${note}` }));
  if (!lines.length) return null;
  return el('ul', { class: 'fly-changes' }, lines);
}

// Each file as a download, and all of them in one zip: each saved under its base name only,
// whatever the server names it (no folder, no `..`: a zip's entry is extracted where it says).
function flyDownloads(plan) {
  const link = (name, blob, cls) => {
    const url = URL.createObjectURL(blob);
    state.flyUrls.push(url);
    return el('a', { href: url, download: name, class: cls, text: name });
  };
  const texts = plan.texts || [];
  const names = uniqueNames(texts.map((t, k) => safeFileName(t.file, `sortie-${k + 1}-of-${texts.length}.txt`)));
  const files = texts.map((t, k) => ({ name: names[k], text: String(t.text) }));
  const links = files.map((f) => link(f.name, new Blob([f.text], { type: 'text/plain;charset=utf-8' }), 'fly-file'));
  const stem = files.length ? files[0].name.replace(/-1-of-\d+\.[^.]+$/, '') : 'plan';
  links.push(link(safeFileName(`${stem}-plan.zip`, 'plan.zip'), zipStored(files), 'fly-all'));
  return el('p', { class: 'fly-downloads' }, ['Files: ', ...links.flatMap((a, k) => (k ? [' ', a] : [a]))]);
}

// Each sortie's flown path in its own colour: its way out and way home dashed.
function drawFly(plan) {
  if (!state.map) return;
  state.flyLayer.clearLayers();
  state.flyLines = [];
  const geo = state.mapGeo;
  const pathOf = (seg) => (geo && seg.points_deg ? seg.points_deg.map((p) => [p[0], p[1]]) : (seg.points_m || []).map((p) => [p[1], p[0]]));
  (plan.maps || []).forEach((m, k) => {
    const colour = sortieColour(k);
    const lines = [];
    for (const [part, dash] of [['way_out', '6 6'], ['route', null], ['way_home', '2 6']]) {
      const latlngs = (m[part] || []).flatMap(pathOf);
      if (!latlngs.length) continue;
      const line = L.polyline(latlngs, {
        color: colour,
        weight: part === 'route' ? 4 : 3,
        opacity: 0.95,
        dashArray: dash,
        className: `fly fly-${part.replace('_', '-')} fly-sortie-${k + 1}`,
        lineCap: 'round',
        lineJoin: 'round',
      });
      const s = plan.sorties[k];
      const band = s.landing_soc ? ` (p5–p95 ${pct(s.landing_soc.p5)}–${pct(s.landing_soc.p95)} %)` : '';
      const tip = tipNode(`sortie ${k + 1} (${m.file}) · ${part.replace('_', ' ')}`, `${fmt(s.energy_wh, 1)} Wh · ${mmss(s.duration_s)} · lands at ${pct(s.end_soc)} %${band}`);
      line.bindTooltip(tip, { sticky: true });
      line.on('mouseover', () => lightSortie(k, true));
      line.on('mouseout', () => lightSortie(k, false));
      line.addTo(state.flyLayer);
      lines.push(line);
    }
    const pnr = m.point_of_no_return;
    if (pnr) {
      const at = geo && pnr.position_deg ? pnr.position_deg : [pnr.position_m[1], pnr.position_m[0]];
      L.circleMarker(at, { radius: 5, className: 'fly-pnr', color: colour, weight: 2, fillColor: '#fff', fillOpacity: 1 })
        .bindTooltip(tipNode(`sortie ${k + 1}: point of no return after ${mmss(pnr.time_s)}`))
        .addTo(state.flyLayer);
    }
    state.flyLines.push(lines);
  });
  drawCuts(plan);
  $('#map').classList.add('flying');
  const bounds = state.flyLayer.getBounds();
  if (bounds.isValid()) state.map.fitBounds(bounds, { padding: [30, 30], maxZoom: geo ? 19 : 4 });
}

// Where each sortie but the last turns home (the last point of its route) and where the next
// resumes the route (the first point of its route): a mark of its own (not a circle, as home
// and the points of no return are), labelled as text with the item of the file that flies to it.
function drawCuts(plan) {
  const maps = plan.maps || [];
  const sorties = plan.sorties || [];
  for (let k = 0; k + 1 < maps.length; k++) {
    const s = sorties[k];
    const cut = routeEnd(maps[k], 'last');
    if (cut) {
      const along = typeof s.ends_inside_leg_fraction === 'number'
        ? `${fmt(s.ends_inside_leg_fraction * 100, 0)} % of the way to mission item ${s.last_item}`
        : s.last_item !== undefined ? `at mission item ${s.last_item}` : null;
      const item = cut.item !== undefined ? `item ${cut.item} of its file` : null;
      const detail = [item, along].filter(Boolean).join(' · ');
      cutMark('cut', k, k, cut, [`sortie ${k + 1} turns home`, detail]);
    }
    const next = sorties[k + 1];
    const back = routeEnd(maps[k + 1], 'first');
    if (back) {
      const item = back.item !== undefined ? `item ${back.item} of its file` : null;
      const towards = next && next.first_item !== undefined ? `on to mission item ${next.first_item}` : null;
      const detail = [item, towards].filter(Boolean).join(' · ');
      cutMark('resume', k + 1, k + 1, back, [`sortie ${k + 2} resumes`, detail]);
    }
  }
}

// The end (`last`) or the start (`first`) of a sortie's route: its position and the file's item
// of the segment that ends there (the route's last segment; for the start, the way out's last).
function routeEnd(m, which) {
  const route = (m && m.route) || [];
  if (!route.length) return null;
  const seg = which === 'last' ? route[route.length - 1] : route[0];
  const pick = (points) => (points && points.length ? points[which === 'last' ? points.length - 1 : 0] : null);
  const metres = pick(seg.points_m);
  if (!metres) return null;
  const out = m.way_out || [];
  const ending = which === 'last' ? seg : out.length ? out[out.length - 1] : seg;
  return { metres, degrees: pick(seg.points_deg), item: ending.item };
}

// One mark (`cut` or `resume`) of sortie k (from 0), in its colour, with its label always shown.
function cutMark(kind, k, colourOf, at, lines) {
  const geo = state.mapGeo;
  const latlng = geo && at.degrees ? [at.degrees[0], at.degrees[1]] : [at.metres[1], at.metres[0]];
  const icon = L.divIcon({ className: `fly-mark fly-${kind} fly-sortie-${k + 1}`, html: el('span'), iconSize: [14, 14] });
  const marker = L.marker(latlng, { icon, keyboard: false, zIndexOffset: 1000 });
  marker.bindTooltip(tipNode(...lines.filter(Boolean)), {
    permanent: true,
    direction: kind === 'cut' ? 'left' : 'right',
    offset: kind === 'cut' ? [-8, 0] : [8, 0],
    className: `fly-mark-label fly-${kind}-label`,
  });
  marker.addTo(state.flyLayer);
  const node = marker.getElement();
  if (!node) return;
  node.style.setProperty('--sortie-colour', sortieColour(colourOf));
  node.dataset.kind = kind;
  node.dataset.sortie = String(k + 1);
  node.dataset.eastM = String(at.metres[0]);
  node.dataset.northM = String(at.metres[1]);
  if (at.degrees) {
    node.dataset.latDeg = String(at.degrees[0]);
    node.dataset.lonDeg = String(at.degrees[1]);
  }
}

function lightSortie(k, on) {
  for (const line of (state.flyLines || [])[k] || []) {
    line.setStyle({ weight: on ? 7 : line.options.className.includes('fly-route') ? 4 : 3 });
    if (on) line.bringToFront();
  }
  const tr = document.querySelector(`#fly tr[data-sortie="${k + 1}"]`);
  if (tr) tr.classList.toggle('highlight', on);
}
