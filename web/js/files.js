// Files opened or dropped on the page: a mission (listed and planned), a vehicle file (sent to
// the server, chosen) or a flight log (read by the server, shown as a card).

import { $, state } from './state.js';
import { el } from './dom.js';
import { basename, duration, fmt } from './format.js';
import { api, clearError, settle, showError } from './api.js';
import { addMission, replan, selectMission } from './mission.js';
import { fillVehicles, syncBatteries } from './vehicles.js';

const MISSION_EXT = /\.(plan|waypoints|toml|json|txt)$/i;
// A `.toml` with a vehicle's table (`[power]`, `[airframe]`, `[propulsion]`, `[[battery]]`)
// and no mission segment (`[[segment]]`) is a vehicle file: sent to POST /api/vehicles. Any
// other `.toml` is a mission (a file is never both: each format refuses the other's keys).
const VEHICLE_TABLE = /^[ \t]*\[\[?[ \t]*(power|airframe|propulsion|battery)[ \t]*\]\]?/m;
const MISSION_TABLE = /^[ \t]*\[\[[ \t]*segment[ \t]*\]\]/m;
const VEHICLE_LIMIT = 256 * 1024;

// A vehicle file sent to the server: kept there under its own name, added to the list (in
// place of one of that name sent before), chosen, and the mission re-planned with it.
async function uploadVehicle(file, text) {
  if (file.size > VEHICLE_LIMIT) {
    showError(`${file.name}: ${file.size} bytes is more than the server accepts for a vehicle file (${VEHICLE_LIMIT})`);
    settle(false);
    return;
  }
  let entry;
  try {
    entry = await api(`/api/vehicles?file=${encodeURIComponent(file.name)}`, {
      method: 'POST',
      body: text,
      headers: { 'Content-Type': 'text/plain' },
    });
  } catch (e) {
    // The server's message names the file.
    showError(e.message);
    settle(false);
    return;
  }
  state.vehicles = state.vehicles.filter((v) => v.name !== entry.name).concat([entry]);
  for (const key of [...state.sweepCache.keys()]) {
    if (key.startsWith(`${entry.name}|`)) state.sweepCache.delete(key);
  }
  state.sweepKey = null;
  fillVehicles();
  $('#vehicle').value = entry.name;
  $('#battery').value = '';
  syncBatteries(null);
  await replan();
}

export function renderLogInfo(info, name) {
  const box = $('#log');
  const placeholder = box.querySelector('p.muted');
  if (placeholder) placeholder.remove();
  const card = el('div', {
    class: 'log-card',
    'data-file': name,
    'data-format': info.format,
    'data-samples': String(info.samples),
  });
  const rows = [];
  const row = (label, value) => rows.push(el('dt', { text: label }), el('dd', { text: value }));
  row('File', basename(info.file || name));
  row('Format', String(info.format));
  row('Duration', duration(info.duration_s));
  row('Samples', String(info.samples));
  row('Energy', typeof info.energy_wh === 'number' ? `${fmt(info.energy_wh, 1)} Wh` : '–');
  row('Power', info.power_available ? `available${typeof info.mean_power_w === 'number' ? ` · mean ${fmt(info.mean_power_w, 0)} W` : ''}` : 'not available');
  const warnings = info.warnings || [];
  card.append(el('dl', { class: 'summary' }, rows));
  if (warnings.length) card.append(el('ul', { class: 'warnings' }, warnings.map((w) => el('li', { text: w }))));
  box.prepend(card);
}

async function uploadLog(file) {
  if (file.size > state.config.max_upload_bytes) {
    showError(`${file.name}: ${file.size} bytes is more than the server accepts (${state.config.max_upload_bytes})`);
    return;
  }
  try {
    const bytes = await file.arrayBuffer();
    const info = await api(`/api/log/info?file=${encodeURIComponent(file.name)}`, {
      method: 'POST',
      body: bytes,
      headers: { 'Content-Type': 'application/octet-stream' },
    });
    renderLogInfo(info, file.name);
    clearError();
    settle(true);
  } catch (e) {
    showError(e.message);
    settle(false);
  }
}

export async function openFiles(files) {
  for (const file of files) {
    try {
      if (MISSION_EXT.test(file.name)) {
        if (file.size > state.config.max_upload_bytes) {
          showError(`${file.name}: ${file.size} bytes is more than the server accepts (${state.config.max_upload_bytes})`);
          continue;
        }
        const text = await file.text();
        if (/\.toml$/i.test(file.name) && VEHICLE_TABLE.test(text) && !MISSION_TABLE.test(text)) {
          await uploadVehicle(file, text);
          continue;
        }
        state.uploads += 1;
        const entry = { key: `upload:${state.uploads}`, label: `${file.name} (opened)`, name: file.name, text };
        addMission(entry);
        await selectMission(entry.key);
      } else {
        await uploadLog(file);
      }
    } catch (e) {
      showError(`${file.name}: ${e.message}`);
      settle(false);
    }
  }
}
