// The mission panel: the missions listed, the plan asked again when the mission or a control
// changes (the summary, the segments table, the map and the charts drawn from its answers).

import { $, body, options, state } from './state.js';
import { el } from './dom.js';
import { distance, duration, fmt, pct, socColour } from './format.js';
import { api, ApiError, busy, clearError, fetchText, settle, showError } from './api.js';
import { highlight, renderMap } from './map.js';
import { renderChart, updateSweep } from './mission-charts.js';
import { clearProfile, renderProfile } from './profile.js';
import { clearFly } from './fly-clear.js';
import { syncBatteries } from './vehicles.js';

export function addMission(entry) {
  state.missions.push(entry);
  const select = $('#mission-select');
  select.append(el('option', { value: entry.key, text: entry.label, title: entry.name || 'built-in demo' }));
}

export async function selectMission(key) {
  const entry = state.missions.find((m) => m.key === key);
  if (!entry) return;
  state.current = entry;
  $('#mission-select').value = key;
  await replan();
}

let debounceTimer = null;
export function replanSoon() {
  if (debounceTimer) clearTimeout(debounceTimer);
  body.dataset.state = 'loading';
  debounceTimer = setTimeout(() => {
    debounceTimer = null;
    replan();
  }, 250);
}

// The re-plan still waiting out its debounce, run now; its promise, or null when none waits.
// "Plan to fly" calls it first: run after the press, that re-plan (of the values just typed, or
// of the `change` a field sends when the press takes its focus) would forget the plan asked for.
export function replanPending() {
  if (!debounceTimer) return null;
  clearTimeout(debounceTimer);
  debounceTimer = null;
  return replan();
}

export async function replan() {
  const seq = ++state.planSeq;
  const entry = state.current;
  // A plan to fly shown was made for the mission and conditions that are changing.
  if (state.flyLayer && $('#fly').dataset.state !== 'none') clearFly();
  busy(1);
  let ok = false;
  try {
    if (!entry) throw new ApiError('no mission selected');
    if (entry.key === 'none') {
      // A live flight without a mission: the map shows the vehicle and its track only.
      state.plan = null;
      clearPlan();
      clearError();
      ok = true;
      return;
    }
    if (entry.text === null) entry.text = await fetchText(`/api/files/${entry.index}`);
    const q = options();
    if (entry.name) q.set('file', entry.name);
    const qs = q.toString();
    const init = { method: 'POST', body: entry.text, headers: { 'Content-Type': 'text/plain' } };
    // both answers, even when one fails, so that nothing is left in flight
    const settled = await Promise.allSettled([api(`/api/mission?${qs}`, init), api(`/api/map?${qs}`, init)]);
    const failure = settled.find((r) => r.status === 'rejected');
    if (failure) throw failure.reason;
    const [mission, map] = settled.map((r) => r.value);
    if (seq !== state.planSeq) return;
    state.plan = { mission, map };
    render(mission, map);
    clearError();
    ok = true;
    await updateSweep(mission).catch((e) => {
      if (seq === state.planSeq) showError(`payload sweep: ${e.message}`);
    });
  } catch (e) {
    if (seq !== state.planSeq) return;
    state.plan = null;
    clearPlan();
    showError(e instanceof Error ? e.message : String(e));
  } finally {
    busy(-1);
    if (seq === state.planSeq) {
      settle(ok);
      state.plans += 1;
      body.dataset.plans = String(state.plans);
    }
  }
}

function clearPlan() {
  const s = $('#summary');
  s.replaceChildren(el('p', { class: 'muted', text: 'No plan.' }));
  delete s.dataset.feasible;
  delete s.dataset.energyWh;
  $('#segments tbody').replaceChildren();
  $('#chart').replaceChildren();
  clearProfile();
  if (state.routeLayer) state.routeLayer.clearLayers();
  state.segLayers.clear();
}

function render(mission, map) {
  renderSummary(mission);
  renderSegments(mission);
  // The profile first: shown or hidden, it sets the map's height before the map fits the route.
  renderProfile(map);
  renderMap(mission, map);
  renderChart(mission, map);
  syncBatteries(mission);
}

function renderSummary(m) {
  const s = $('#summary');
  s.dataset.feasible = String(m.feasible);
  s.dataset.energyWh = String(m.energy_wh);
  const rows = [];
  const row = (label, value, cls) => rows.push(el('dt', { text: label }), el('dd', { class: cls }, [value]));
  row('Mission', m.mission);
  row('Vehicle', `${m.vehicle} · ${m.battery}`);
  if (typeof m.air_density_kg_m3 === 'number') {
    const where = [];
    if (typeof m.elevation_m === 'number') where.push(`${fmt(m.elevation_m, 0)} m`);
    if (typeof m.temperature_c === 'number') where.push(`${fmt(m.temperature_c, 1)} °C`);
    row('Air', `${fmt(m.air_density_kg_m3, 3)} kg/m³${where.length ? ' (' + where.join(', ') + ')' : ''}`);
  }
  row('Feasible', m.feasible ? 'yes' : `no${m.reason ? ' — ' + m.reason : ''}`, m.feasible ? 'good' : 'bad');
  row('Duration', duration(m.duration_s));
  row('Distance', distance(m.distance_m));
  row('Energy', `${fmt(m.energy_wh, 1)} Wh`);
  row('Landing', `${pct(m.end_soc)} % battery`);
  const reserveOk = typeof m.reserve_soc === 'number' && m.reserve_soc >= m.required_reserve_soc;
  row('Reserve', `${pct(m.reserve_soc)} % (required ${pct(m.required_reserve_soc, 0)} %)`, reserveOk ? 'good' : 'bad');
  if (m.point_of_no_return_s !== undefined && m.point_of_no_return_s !== null) {
    row('No return', `after ${duration(m.point_of_no_return_s)}`);
  }
  if (m.batteries_required !== undefined && m.batteries_required !== null) {
    row('Batteries', `${m.batteries_required}${m.sorties && m.sorties.length > 1 ? ` (${m.sorties.length} sorties)` : ''}`);
  }
  const dl = el('dl', { class: 'summary' }, rows);
  const children = [dl];
  const warnings = (m.warnings || []).concat((m.route && m.route.warnings) || []);
  const unique = [...new Set(warnings)];
  if (unique.length) {
    children.push(el('ul', { class: 'warnings' }, unique.map((w) => el('li', { text: w }))));
  }
  s.replaceChildren(...children);
}

function renderSegments(m) {
  const tbody = $('#segments tbody');
  const rows = (m.segments || []).map((seg) => {
    const note = [];
    if (seg.limit) note.push(String(seg.limit));
    if (typeof seg.time_lost_s === 'number' && seg.time_lost_s > 0) note.push(`+${fmt(seg.time_lost_s, 1)} s`);
    const tr = el('tr', {
      'data-index': String(seg.index),
      'data-item': seg.item !== undefined && seg.item !== null ? String(seg.item) : undefined,
      'data-kind': seg.kind,
      'data-energy-wh': String(seg.energy_wh),
      'data-end-soc': String(seg.end_soc),
      'data-duration-s': String(seg.duration_s),
      class: typeof seg.end_soc === 'number' && seg.end_soc < m.required_reserve_soc ? 'below-reserve' : undefined,
    }, [
      el('td', { class: 'n', text: String(seg.index) }),
      el('td', { class: 'n', text: seg.item !== undefined && seg.item !== null ? String(seg.item) : '' }),
      el('td', { text: seg.kind }),
      el('td', { class: 'n', text: fmt(seg.duration_s, 1) }),
      el('td', { class: 'n', text: fmt(seg.distance_m, 0) }),
      el('td', { class: 'n', text: fmt(seg.energy_wh, 2) }),
      el('td', { class: 'n', text: fmt(seg.mean_power_w, 0) }),
      el('td', { class: 'n', text: fmt(seg.peak_power_w, 0) }),
      el('td', { class: 'n' }, [
        el('span', { class: 'swatch', style: `background:${socColour(seg.end_soc, m.required_reserve_soc)}` }),
        pct(seg.end_soc),
      ]),
    ]);
    if (note.length) {
      tr.title = note.join(', ');
      tr.cells[2].append(el('span', { class: 'flag', text: ' *' }));
    }
    tr.addEventListener('mouseenter', () => highlight(seg.index, true));
    tr.addEventListener('mouseleave', () => highlight(seg.index, false));
    return tr;
  });
  tbody.replaceChildren(...rows);
}
