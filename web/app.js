// The page of `aloft serve`: ES modules, no build step (this is the entry: the controls wired,
// the configuration loaded, the first mission planned). Talks to the JSON API of the same server.
//
// Every value from a file, a request or the server goes into the page as text (`js/dom.js`); no
// markup is built from strings anywhere; the server's Content-Security-Policy (no inline script)
// holds if a spot is ever missed.

import { $, body, state } from './js/state.js';
import { basename } from './js/format.js';
import { api, settle, showError } from './js/api.js';
import { ensureMap } from './js/map.js';
import { startLive } from './js/live.js';
import { addMission, replanSoon, selectMission } from './js/mission.js';
import { planToFly } from './js/fly.js';
import { fillVehicles, syncBatteries } from './js/vehicles.js';
import { openFiles, renderLogInfo } from './js/files.js';
import { followInLogbook, loadLogbook } from './js/logbook.js';

function wire() {
  $('#mission-select').addEventListener('change', (e) => {
    selectMission(e.target.value);
  });
  $('#vehicle').addEventListener('change', () => {
    syncBatteries(state.plan && state.plan.mission);
    $('#battery').value = '';
    followInLogbook();
    replanSoon();
  });
  for (const id of ['#battery', '#payload', '#wind-speed', '#wind-from', '#reserve', '#elevation', '#temperature', '#samples']) {
    const input = $(id);
    input.addEventListener('input', replanSoon);
    input.addEventListener('change', replanSoon);
  }
  // The controls are not a form to send: Enter in a field changes nothing but the field.
  $('#controls').addEventListener('submit', (e) => e.preventDefault());
  $('#plan-fly').addEventListener('click', () => {
    planToFly();
  });
  $('#file').addEventListener('change', (e) => {
    const files = [...(e.target.files || [])];
    e.target.value = '';
    openFiles(files);
  });
  let depth = 0;
  window.addEventListener('dragenter', (e) => {
    e.preventDefault();
    depth += 1;
    body.classList.add('dragging');
  });
  window.addEventListener('dragleave', () => {
    depth = Math.max(0, depth - 1);
    if (depth === 0) body.classList.remove('dragging');
  });
  window.addEventListener('dragover', (e) => {
    e.preventDefault();
    if (e.dataTransfer) e.dataTransfer.dropEffect = 'copy';
  });
  window.addEventListener('drop', (e) => {
    e.preventDefault();
    depth = 0;
    body.classList.remove('dragging');
    const files = e.dataTransfer ? [...e.dataTransfer.files] : [];
    if (files.length) openFiles(files);
  });
  window.addEventListener('resize', () => {
    if (state.map) state.map.invalidateSize();
  });
  window.addEventListener('unhandledrejection', (e) => {
    e.preventDefault();
    showError(e.reason && e.reason.message ? e.reason.message : String(e.reason));
  });
}

async function start() {
  body.dataset.state = 'loading';
  body.dataset.plans = '0';
  wire();
  try {
    const [config, vehicles] = await Promise.all([api('/api/config'), api('/api/vehicles')]);
    state.config = Object.assign({ files: [], live: false, max_upload_bytes: Infinity }, config);
    state.vehicles = Array.isArray(vehicles) ? vehicles : [];
  } catch (e) {
    showError(`cannot load the configuration: ${e.message}`);
    settle(false);
    return;
  }
  fillVehicles();
  const liveOnly = state.config.live && !state.config.files.some((f) => f.kind === 'mission');
  if (liveOnly) addMission({ key: 'none', label: 'none (the live flight)', name: null, text: '' });
  addMission({ key: 'demo', label: 'demo survey (built in)', name: null, text: '' });
  let first = null;
  for (const f of state.config.files) {
    if (f.kind === 'mission') {
      const entry = { key: `file:${f.index}`, label: basename(f.name), name: f.name, text: null, index: f.index };
      addMission(entry);
      if (!first) first = entry;
    }
  }
  if (state.config.live) startLive();
  ensureMap(false);
  const logs = state.config.files.filter((f) => f.kind === 'log');
  const logLoads = logs.map((f) =>
    api(`/api/files/${f.index}/info`)
      .then((info) => renderLogInfo(info, f.name))
      .catch((e) => showError(`${basename(f.name)}: ${e.message}`)),
  );
  const logbookLoad = state.config.logbook
    ? loadLogbook().catch((e) => showError(`logbook: ${e.message}`))
    : Promise.resolve();
  await selectMission(first ? first.key : liveOnly ? 'none' : 'demo');
  await Promise.all(logLoads);
  await logbookLoad;
  settle(!$('#error').textContent);
}

start().catch((e) => {
  showError(e && e.message ? e.message : String(e));
  body.dataset.state = 'error';
});
