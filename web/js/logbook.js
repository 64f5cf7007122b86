// The logbook panel: each vehicle's power and each pack's resistance per flight.

import { $, state } from './state.js';
import { el } from './dom.js';
import { fmt, SORTIE_COLOURS } from './format.js';
import { api } from './api.js';
import { historyChart } from './chart.js';

// The logbook's lists (`/api/logbook/vehicles`, `/api/logbook/packs`).
const logbook = { vehicles: [], packs: [] };

function renderLogbookVehicle(v) {
  const drift = v.power_drift && v.power_drift.trend.change_percent != null
    ? `; ${v.power_drift.quantity === 'hover_power_w' ? 'hover' : 'mean'} power ${v.power_drift.trend.change_percent >= 0 ? '+' : ''}${fmt(v.power_drift.trend.change_percent, 1)} % over the last ${v.power_drift.trend.n} flights`
    : '';
  $('#logbook-vehicle-summary').textContent = `${v.key}: ${v.flights} flights, ${fmt(v.hours, 2)} h, ${fmt(v.energy_wh, 1)} Wh${drift}`;
  const num = (x) => (typeof x === 'number' ? x : NaN);
  historyChart($('#logbook-vehicle-chart'), `power per flight of ${v.key}`, 'power (W)', [
    { name: 'mean power', cls: 'mean-power', values: v.power.map((p) => num(p.mean_power_w)) },
    { name: 'hover power', cls: 'hover-power', values: v.power.map((p) => num(p.hover_power_w)) },
  ]);
}

// The pack's summary, and the resistance of each pack of the chosen vehicle (and of this pack),
// one line each, this one drawn over the others.
function renderLogbookPack(p) {
  const cycles = typeof p.equivalent_cycles !== 'number' ? 'cycles n/a (no rated capacity)' : `${fmt(p.equivalent_cycles, 2)} equivalent cycles`;
  const t = p.resistance_trend;
  const trend = t ? `; resistance ${fmt(t.first * 1000, 1)} to ${fmt(t.last * 1000, 1)} mOhm over ${t.n} flights` : '';
  $('#logbook-pack-summary').textContent = `${p.key}: ${p.flights} flights, ${fmt(p.discharged_mah, 0)} mAh, ${cycles}${trend}`;
  const vehicle = logbook.vehicles[Number($('#logbook-vehicle').value)];
  const keys = ((vehicle && vehicle.packs) || []).filter((k) => k !== p.key);
  const others = logbook.packs.filter((q) => keys.includes(q.key));
  const series = others.concat([p]).map((q, k) => ({
    name: q.key,
    cls: q === p ? 'resistance selected' : 'resistance other',
    colour: q === p ? undefined : SORTIE_COLOURS[k % SORTIE_COLOURS.length],
    values: (q.resistance || []).map((r) => r.value * 1000),
  }));
  historyChart($('#logbook-pack-chart'), `resistance per flight of ${p.key}`, 'resistance (mOhm)', series);
}

// The logbook's vehicle the page opens on: the one the page flies (its name, in any case),
// else the one with the latest flight, else the first with a key of its own (the flights of
// "unknown" are of any vehicle).
function openingVehicle(vehicles) {
  const flown = String($('#vehicle').value || state.config.default_vehicle || '').trim().toLowerCase();
  const same = vehicles.findIndex((v) => String(v.key).trim().toLowerCase() === flown);
  if (same >= 0) return same;
  const latest = (v) => Math.max(-Infinity, ...(v.power || []).map((p) => (typeof p.start_unix_s === 'number' ? p.start_unix_s : -Infinity)));
  let best = -1;
  vehicles.forEach((v, i) => {
    if (latest(v) > (best >= 0 ? latest(vehicles[best]) : -Infinity)) best = i;
  });
  return best >= 0 ? best : Math.max(0, vehicles.findIndex((v) => v.key !== 'unknown'));
}

// The pack the panel opens on for vehicle `v`: its first pack in the logbook, else the first
// with a key of its own.
function openingPack(v, packs) {
  const own = packs.findIndex((p) => v && (v.packs || []).includes(p.key));
  return own >= 0 ? own : Math.max(0, packs.findIndex((p) => p.key !== 'unknown'));
}

function fillLogbookSelect(select, items) {
  select.replaceChildren(...items.map((x, i) => el('option', { value: String(i) }, [`${x.key} (${x.flights} flights)`])));
}

// Show vehicle `i` of the logbook, and the pack it opens on.
function showLogbookVehicle(i) {
  const v = logbook.vehicles[i];
  $('#logbook-vehicle').value = String(i);
  if (v) renderLogbookVehicle(v);
  const k = openingPack(v, logbook.packs);
  $('#logbook-pack').value = String(k);
  if (logbook.packs[k]) renderLogbookPack(logbook.packs[k]);
}

// The logbook's panel follows the vehicle chosen on the page when the logbook has it.
export function followInLogbook() {
  if (!logbook.vehicles.length) return;
  const flown = String($('#vehicle').value).trim().toLowerCase();
  const i = logbook.vehicles.findIndex((v) => String(v.key).trim().toLowerCase() === flown);
  if (i >= 0) showLogbookVehicle(i);
}

export async function loadLogbook() {
  const [vehicles, packs] = await Promise.all([api('/api/logbook/vehicles'), api('/api/logbook/packs')]);
  logbook.vehicles = vehicles.vehicles || [];
  logbook.packs = packs.packs || [];
  $('#logbook-panel').hidden = false;
  fillLogbookSelect($('#logbook-vehicle'), logbook.vehicles);
  fillLogbookSelect($('#logbook-pack'), logbook.packs);
  $('#logbook-vehicle').onchange = () => showLogbookVehicle(Number($('#logbook-vehicle').value));
  $('#logbook-pack').onchange = () => {
    const p = logbook.packs[Number($('#logbook-pack').value)];
    if (p) renderLogbookPack(p);
  };
  showLogbookVehicle(openingVehicle(logbook.vehicles));
}
