// The vehicle and battery lists of the controls.

import { $, state } from './state.js';
import { el } from './dom.js';

// The server's vehicles (built-in, given, sent), its default (the first --vehicle) chosen.
export function fillVehicles() {
  const select = $('#vehicle');
  select.replaceChildren(...state.vehicles.map((v) => el('option', { value: v.name, text: v.name, title: v.description })));
  const chosen = state.config.default_vehicle;
  if (chosen && state.vehicles.some((v) => v.name === chosen)) select.value = chosen;
}

// The battery list follows the chosen vehicle (or the answer's vehicle when on the default).
export function syncBatteries(mission) {
  const select = $('#battery');
  const name = $('#vehicle').value || (mission && mission.vehicle);
  const vehicle = state.vehicles.find((v) => v.name === name);
  const packs = vehicle ? vehicle.batteries : [];
  const current = select.value;
  const have = [...select.options].slice(1).map((o) => o.value);
  // The server's pack for its default vehicle (`aloft serve --battery`), else the vehicle's.
  const own = name === state.config.default_vehicle && state.config.default_battery;
  const label = own ? `default (${state.config.default_battery})` : 'default';
  if (have.join('|') !== packs.join('|') || select.options[0].textContent !== label) {
    select.replaceChildren(el('option', { value: '', text: label }), ...packs.map((b) => el('option', { value: b, text: b })));
    select.value = packs.includes(current) ? current : '';
  }
}
