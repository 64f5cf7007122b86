// The live panel: telemetry from `/api/live` (server-sent events), the vehicle and its track on
// the map.

import { $, state } from './state.js';
import { el, tipNode } from './dom.js';
import { duration, fmt, pct } from './format.js';

export function startLive() {
  const panel = $('#live');
  panel.hidden = false;
  if (typeof EventSource === 'undefined') {
    panel.querySelector('.live-body').textContent = 'this browser has no EventSource';
    return;
  }
  const source = new EventSource('/api/live');
  source.addEventListener('update', (ev) => {
    let u;
    try {
      u = JSON.parse(ev.data);
    } catch (e) {
      return;
    }
    state.lastLive = u;
    renderLive(u);
    drawLive(u);
  });
  source.addEventListener('end', (ev) => {
    source.close();
    let d = {};
    try {
      d = JSON.parse(ev.data);
    } catch (e) {
      /* keep empty */
    }
    const note = panel.querySelector('.live-end') || el('p', { class: 'live-end' });
    if (d.error) {
      note.textContent = `telemetry ended: ${d.error}`;
      note.classList.add('bad');
    } else {
      note.textContent = 'flight ended';
      if (d.summary && typeof d.summary === 'object') {
        const s = d.summary;
        const bits = [];
        if (typeof s.duration_s === 'number') bits.push(duration(s.duration_s));
        if (typeof s.energy_wh === 'number') bits.push(`${fmt(s.energy_wh, 1)} Wh`);
        if (typeof s.energy_used_wh === 'number') bits.push(`${fmt(s.energy_used_wh, 1)} Wh used`);
        if (bits.length) note.textContent += ` (${bits.join(', ')})`;
      }
    }
    panel.append(note);
    panel.dataset.ended = 'true';
  });
  source.onerror = () => {
    if (source.readyState === EventSource.CLOSED) panel.dataset.ended = 'true';
  };
}

function renderLive(u) {
  const panel = $('#live');
  panel.dataset.mode = u.mode || '';
  panel.dataset.advice = u.advice || '';
  panel.dataset.time = String(u.time_s);
  const rows = [];
  const row = (label, value, cls) => rows.push(el('dt', { text: label }), el('dd', { class: cls, text: value }));
  row('Mode', `${u.mode || '–'}${u.in_air ? ' · in the air' : ' · on the ground'}${u.mission_item !== undefined && u.mission_item !== null ? ` · item ${u.mission_item}` : ''}`);
  row('Time', duration(u.time_s));
  row('Battery', typeof u.soc === 'number' ? `${pct(u.soc, 0)} %` : '–');
  row('Used', `${fmt(u.energy_used_wh, 1)} Wh`);
  if (u.remaining_wh) {
    row('Remaining', `${fmt(u.remaining_wh.p5, 1)} / ${fmt(u.remaining_wh.p50, 1)} / ${fmt(u.remaining_wh.p95, 1)} Wh (p5/p50/p95)`);
  }
  if (u.advice) row('Advice', u.advice, u.advice === 'continue' ? 'good' : 'bad');
  // What aloft live does not believe, or assumes (the state of charge's source), as it says it.
  if (u.note) row('Note', u.note, 'note');
  panel.querySelector('.live-body').replaceChildren(el('dl', { class: 'summary' }, rows));
}

export function drawLive(u) {
  if (!state.map || !u.position) return;
  const p = u.position;
  let at;
  if (state.mapGeo && typeof p.latitude_deg === 'number' && typeof p.longitude_deg === 'number') at = [p.latitude_deg, p.longitude_deg];
  else at = [p.north_m, p.east_m];
  if (!at.every(Number.isFinite)) return;
  state.liveTrack.push(at);
  if (state.liveTrack.length > 5000) state.liveTrack.shift();
  if (!state.liveTrackLine) {
    state.liveTrackLine = L.polyline(state.liveTrack, { className: 'track', color: '#0d47a1', weight: 2, opacity: 0.7, dashArray: '4 4', interactive: false }).addTo(state.liveLayer);
  } else {
    state.liveTrackLine.setLatLngs(state.liveTrack);
  }
  if (!state.liveMarker) {
    state.liveMarker = L.circleMarker(at, { radius: 8, className: 'vehicle', color: '#0d47a1', weight: 3, fillColor: '#42a5f5', fillOpacity: 1 }).addTo(state.liveLayer);
    state.liveMarker.bindTooltip(tipNode('vehicle'));
  } else {
    state.liveMarker.setLatLng(at);
  }
  // The map follows the vehicle: back into view when it leaves it.
  if (!state.map.getBounds().contains(at)) state.map.panTo(at);
}
