// The page of `aloft serve`: plain JS, no build step. Talks to the JSON API of the same server.
//
// Every value from a file, a request or the server goes into the page as text: elements are
// built with `el`/`svg` (text nodes, `textContent`, attributes), Leaflet's tooltips are given
// nodes (`tipNode`), never a string (Leaflet parses a string as markup), and the tile layer's
// attribution is escaped (`escaped`). No markup is built from strings anywhere; the server's
// Content-Security-Policy (no inline script) holds if a spot is ever missed.
(function () {
  'use strict';

  const MISSION_EXT = /\.(plan|waypoints|toml|json|txt)$/i;
  // A `.toml` with a vehicle's table (`[power]`, `[airframe]`, `[propulsion]`, `[[battery]]`)
  // and no mission segment (`[[segment]]`) is a vehicle file: sent to POST /api/vehicles. Any
  // other `.toml` is a mission (a file is never both: each format refuses the other's keys).
  const VEHICLE_TABLE = /^[ \t]*\[\[?[ \t]*(power|airframe|propulsion|battery)[ \t]*\]\]?/m;
  const MISSION_TABLE = /^[ \t]*\[\[[ \t]*segment[ \t]*\]\]/m;
  const VEHICLE_LIMIT = 256 * 1024;
  const SVG_NS = 'http://www.w3.org/2000/svg';

  const $ = (sel) => document.querySelector(sel);
  const body = document.body;

  const state = {
    config: { files: [], live: false, max_upload_bytes: Infinity },
    vehicles: [],
    missions: [], // {key, label, name (file= parameter, or null), text (null: not fetched), index?}
    current: null, // the selected entry of missions
    plan: null, // {mission, map}
    planSeq: 0,
    plans: 0,
    inflight: 0,
    sweepKey: null,
    sweepCache: new Map(),
    map: null,
    mapGeo: null, // true: geographic (tiles), false: CRS.Simple
    routeLayer: null,
    segLayers: new Map(), // segment index -> polyline
    liveLayer: null,
    flyLayer: null, // the sorties of the plan to fly
    flyLines: [], // sortie -> its polylines
    flyUrls: [], // the plan's download links (object URLs)
    flySeq: 0,
    liveMarker: null,
    liveTrackLine: null,
    liveTrack: [],
    lastLive: null,
    uploads: 0,
  };

  // ---------------------------------------------------------------- helpers

  function el(tag, attrs, children) {
    const e = document.createElement(tag);
    if (attrs) {
      for (const [k, v] of Object.entries(attrs)) {
        if (v === undefined || v === null) continue;
        if (k === 'class') e.className = v;
        else if (k === 'text') e.textContent = v;
        // Through the CSS object model: the page's policy allows no inline style attribute.
        else if (k === 'style') e.style.cssText = v;
        else e.setAttribute(k, v);
      }
    }
    for (const c of children || []) {
      if (c === null || c === undefined) continue;
      e.append(c instanceof Node ? c : document.createTextNode(String(c)));
    }
    return e;
  }

  function svg(tag, attrs, text) {
    const e = document.createElementNS(SVG_NS, tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (v !== undefined && v !== null) e.setAttribute(k, String(v));
    }
    if (text !== undefined) e.textContent = text;
    return e;
  }

  // A tooltip's content: its lines as text nodes (Leaflet puts a node in as it is, where it
  // would parse a string as markup).
  function tipNode(...lines) {
    const box = el('div', { class: 'tip' });
    lines.forEach((line, k) => {
      if (k) box.append(el('br'));
      box.append(String(line));
    });
    return box;
  }

  // `text` with the characters of markup escaped, for the one place a library takes markup and
  // no node (the tile layer's attribution).
  function escaped(text) {
    return String(text).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);
  }

  // A name to save a file under: its last path component (whatever the server says), without
  // control characters, `..` or a leading dot; `fallback` when nothing is left.
  function safeFileName(name, fallback) {
    const base = String(name === undefined || name === null ? '' : name).split(/[\\/]/).pop();
    const clean = base
      .replace(/[\u0000-\u001f\u007f:*?"<>|]/g, '_')
      .replace(/\.{2,}/g, '.')
      .replace(/^[.\s]+/, '')
      .trim();
    return clean || fallback;
  }

  // Names made unique in their order (`name (2).ext` for a second `name.ext`).
  function uniqueNames(names) {
    const seen = new Set();
    return names.map((n) => {
      let out = n;
      for (let k = 2; seen.has(out); k++) out = n.replace(/(\.[^.]*)?$/, (ext) => ` (${k})${ext}`);
      seen.add(out);
      return out;
    });
  }

  function fmt(x, digits) {
    if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
    return x.toLocaleString('en-US', { minimumFractionDigits: digits, maximumFractionDigits: digits });
  }

  function pct(soc, digits) {
    return typeof soc === 'number' ? fmt(soc * 100, digits === undefined ? 1 : digits) : '–';
  }

  function duration(s) {
    if (typeof s !== 'number' || !Number.isFinite(s)) return '–';
    const total = Math.round(s);
    const m = Math.floor(total / 60);
    const sec = total % 60;
    return m > 0 ? `${m} min ${String(sec).padStart(2, '0')} s` : `${sec} s`;
  }

  function distance(m) {
    if (typeof m !== 'number') return '–';
    return m >= 1000 ? `${fmt(m / 1000, 2)} km` : `${fmt(m, 0)} m`;
  }

  function basename(path) {
    return String(path).split(/[\\/]/).pop();
  }

  function busy(delta) {
    state.inflight += delta;
    if (state.inflight > 0) body.dataset.state = 'loading';
  }

  function settle(ok) {
    if (state.inflight > 0) return;
    body.dataset.state = ok ? 'ready' : 'error';
  }

  class ApiError extends Error {}

  // Fetch JSON; a 4xx/5xx answer's {"error"} becomes an ApiError with that message.
  async function api(url, options) {
    busy(1);
    try {
      let response;
      try {
        response = await fetch(url, options);
      } catch (e) {
        throw new ApiError(`the server did not answer (${e && e.message ? e.message : 'network error'})`);
      }
      const text = await response.text();
      let data = null;
      try {
        data = text ? JSON.parse(text) : null;
      } catch (e) {
        if (response.ok) throw new ApiError(`unreadable answer from ${url.split('?')[0]}`);
      }
      if (!response.ok) {
        const message = data && typeof data.error === 'string' ? data.error : `${response.status} ${response.statusText}`;
        throw new ApiError(message);
      }
      return data;
    } finally {
      busy(-1);
    }
  }

  function showError(message) {
    const e = $('#error');
    e.textContent = message;
    e.hidden = false;
  }

  function clearError() {
    const e = $('#error');
    e.textContent = '';
    e.hidden = true;
  }

  // Colour of a state of charge: green at full, amber half-way to the reserve, red at the reserve.
  function socColour(soc, reserve) {
    const r = typeof reserve === 'number' ? reserve : 0.2;
    if (typeof soc !== 'number') return '#777';
    if (soc < r) return '#8b0000';
    const f = Math.max(0, Math.min(1, (soc - r) / Math.max(1e-9, 1 - r)));
    // red (0) -> amber (0.5) -> green (1), in HSL hue 0..130
    const hue = Math.round(f * 130);
    return `hsl(${hue}, 75%, 40%)`;
  }

  // ---------------------------------------------------------------- options

  function options() {
    const q = new URLSearchParams();
    const add = (key, value) => {
      const v = String(value === undefined || value === null ? '' : value).trim();
      if (v !== '') q.set(key, v);
    };
    add('vehicle', $('#vehicle').value);
    add('battery', $('#battery').value);
    add('payload_kg', $('#payload').value);
    add('wind_speed', $('#wind-speed').value);
    add('wind_from', $('#wind-from').value);
    add('reserve_percent', $('#reserve').value);
    add('elevation_m', $('#elevation').value);
    add('temperature_c', $('#temperature').value);
    const samples = $('#samples').value.trim();
    if (samples !== '' && Number(samples) !== 0) q.set('samples', samples);
    return q;
  }

  // ---------------------------------------------------------------- missions

  function addMission(entry) {
    state.missions.push(entry);
    const select = $('#mission-select');
    select.append(el('option', { value: entry.key, text: entry.label, title: entry.name || 'built-in demo' }));
  }

  async function fetchText(url) {
    busy(1);
    try {
      const r = await fetch(url);
      const text = await r.text();
      if (!r.ok) {
        let message = `${r.status} ${r.statusText}`;
        try {
          const d = JSON.parse(text);
          if (d && d.error) message = d.error;
        } catch (e) {
          /* not JSON */
        }
        throw new ApiError(message);
      }
      return text;
    } finally {
      busy(-1);
    }
  }

  async function selectMission(key) {
    const entry = state.missions.find((m) => m.key === key);
    if (!entry) return;
    state.current = entry;
    $('#mission-select').value = key;
    await replan();
  }

  // ---------------------------------------------------------------- re-plan

  let debounceTimer = null;
  function replanSoon() {
    if (debounceTimer) clearTimeout(debounceTimer);
    body.dataset.state = 'loading';
    debounceTimer = setTimeout(() => {
      debounceTimer = null;
      replan();
    }, 250);
  }

  async function replan() {
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
    if (state.routeLayer) state.routeLayer.clearLayers();
    state.segLayers.clear();
  }

  function render(mission, map) {
    renderSummary(mission);
    renderSegments(mission);
    renderMap(mission, map);
    renderChart(mission, map);
    syncBatteries(mission);
  }

  // ---------------------------------------------------------------- summary

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

  // ---------------------------------------------------------------- segments table

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

  function highlight(index, on) {
    const layer = state.segLayers.get(index);
    if (layer) {
      layer.setStyle({ weight: on ? 9 : 5, opacity: on ? 1 : 0.9 });
      const path = layer.getElement && layer.getElement();
      if (path) path.classList.toggle('highlight', on);
      if (on) layer.bringToFront();
    }
    const tr = document.querySelector(`#segments tbody tr[data-index="${index}"]`);
    if (tr) tr.classList.toggle('highlight', on);
  }

  // ---------------------------------------------------------------- map

  function ensureMap(geo) {
    if (state.map && state.mapGeo === geo) return state.map;
    if (state.map) {
      state.map.remove();
      state.map = null;
    }
    const container = $('#map');
    container.classList.toggle('plain', !geo);
    let map;
    if (geo) {
      map = L.map(container, { zoomControl: true });
      L.tileLayer(state.config.tiles, {
        // Leaflet puts an attribution in as markup: the operator's text is shown as text.
        attribution: escaped(state.config.attribution || ''),
        maxZoom: 19,
      }).addTo(map);
    } else {
      map = L.map(container, {
        crs: L.CRS.Simple,
        minZoom: -6,
        maxZoom: 6,
        zoomSnap: 0.25,
        attributionControl: false,
      });
    }
    L.control.scale({ imperial: false }).addTo(map);
    colourLegend().addTo(map);
    map.setView([0, 0], geo ? 2 : 0);
    state.map = map;
    state.mapGeo = geo;
    state.routeLayer = L.featureGroup().addTo(map);
    state.flyLayer = L.featureGroup().addTo(map);
    state.liveLayer = L.featureGroup().addTo(map);
    state.liveMarker = null;
    state.liveTrackLine = null;
    state.liveTrack = [];
    state.segLayers.clear();
    if (state.lastLive) drawLive(state.lastLive);
    return map;
  }

  // The legend of the legs' colours: battery at the end of each leg, from the reserve to full.
  function colourLegend() {
    const legend = L.control({ position: 'bottomright' });
    legend.onAdd = () => {
      const box = L.DomUtil.create('div', 'map-legend');
      box.id = 'map-legend';
      const stops = [0, 0.25, 0.5, 0.75, 1].map((f) => `hsl(${Math.round(f * 130)}, 75%, 40%) ${f * 100}%`);
      const bar = L.DomUtil.create('div', 'map-legend-bar', box);
      bar.style.background = `linear-gradient(to right, ${stops.join(', ')})`;
      const labels = L.DomUtil.create('div', 'map-legend-labels', box);
      labels.append(...['reserve', 'battery at leg end', 'full'].map((t) => el('span', { text: t })));
      return box;
    };
    return legend;
  }

  function isGeo(mapAnswer) {
    return Boolean(state.config.tiles && mapAnswer && mapAnswer.home);
  }

  function renderMap(mission, mapAnswer) {
    const geo = isGeo(mapAnswer);
    const map = ensureMap(geo);
    state.routeLayer.clearLayers();
    state.segLayers.clear();
    const bySeg = new Map((mission.segments || []).map((s) => [s.index, s]));
    const pathOf = (seg) => {
      if (geo && seg.points_deg) return seg.points_deg.map((p) => [p[0], p[1]]);
      return (seg.points_m || []).map((p) => [p[1], p[0]]);
    };
    const paths = new Map();
    for (const seg of mapAnswer.segments || []) {
      const latlngs = pathOf(seg);
      paths.set(seg.index, latlngs);
      if (!latlngs.length) continue;
      const ms = bySeg.get(seg.index);
      const soc = ms ? ms.end_soc : undefined;
      const colour = socColour(soc, mission.required_reserve_soc);
      const line = L.polyline(latlngs, {
        color: colour,
        weight: 5,
        opacity: 0.9,
        className: `seg seg-${String(seg.kind).replace(/[^a-z0-9-]/gi, '')}`,
        lineCap: 'round',
        lineJoin: 'round',
      });
      const item = seg.item !== undefined && seg.item !== null ? `item ${seg.item} · ` : '';
      const head = `${item}${seg.kind} (segment ${seg.index})`;
      const tip = ms ? tipNode(head, `${fmt(ms.energy_wh, 2)} Wh · battery ${pct(ms.end_soc)} %`) : tipNode(head);
      line.bindTooltip(tip, { sticky: true });
      line.on('mouseover', () => highlight(seg.index, true));
      line.on('mouseout', () => highlight(seg.index, false));
      line.addTo(state.routeLayer);
      const path = line.getElement();
      if (path) path.dataset.index = String(seg.index);
      state.segLayers.set(seg.index, line);
    }
    // home
    const home = geo ? [mapAnswer.home.latitude_deg, mapAnswer.home.longitude_deg] : [0, 0];
    L.circleMarker(home, { radius: 7, className: 'home', color: '#1f3b73', weight: 2, fillColor: '#fff', fillOpacity: 1 })
      .bindTooltip(tipNode('home'))
      .addTo(state.routeLayer);
    // ends of sorties
    for (const sortie of mission.sorties || []) {
      const latlngs = paths.get(sortie.last_segment);
      if (!latlngs || !latlngs.length) continue;
      const end = latlngs[latlngs.length - 1];
      L.circleMarker(end, { radius: 6, className: 'sortie-end', color: '#333', weight: 2, fillColor: '#ffd54f', fillOpacity: 1 })
        .bindTooltip(tipNode(`end of sortie (segment ${sortie.last_segment}): battery ${pct(sortie.end_soc)} %`))
        .addTo(state.routeLayer);
    }
    // point of no return
    const pnr = mapAnswer.point_of_no_return;
    if (pnr) {
      const at = geo && pnr.position_deg ? pnr.position_deg : [pnr.position_m[1], pnr.position_m[0]];
      L.circleMarker(at, { radius: 8, className: 'pnr', color: '#b00020', weight: 3, fillColor: '#fff', fillOpacity: 1 })
        .bindTooltip(tipNode(`point of no return: ${duration(pnr.time_s)} (segment ${pnr.segment})`))
        .addTo(state.routeLayer);
    }
    map.invalidateSize();
    const bounds = state.routeLayer.getBounds();
    if (bounds.isValid()) {
      const flat = bounds.getNorth() === bounds.getSouth() && bounds.getEast() === bounds.getWest();
      if (flat) map.setView(bounds.getCenter(), geo ? 17 : 0);
      else map.fitBounds(bounds, { padding: [30, 30], maxZoom: geo ? 19 : 4 });
    }
  }

  // ---------------------------------------------------------------- charts

  function niceTicks(lo, hi, count) {
    if (!(hi > lo)) hi = lo + 1;
    const raw = (hi - lo) / Math.max(1, count);
    const mag = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 2.5, 5, 10].map((f) => f * mag).find((s) => s >= raw) || 10 * mag;
    const ticks = [];
    for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) ticks.push(Number(v.toFixed(10)));
    return ticks;
  }

  // A frame with axes; returns {root, x(v), y(v), plot} for drawing.
  function frame(container, opts) {
    const W = 560;
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

  function points(xs, ys, fx, fy) {
    const out = [];
    const n = Math.min(xs.length, ys.length);
    for (let i = 0; i < n; i++) {
      if (Number.isFinite(xs[i]) && Number.isFinite(ys[i])) out.push(`${fx(xs[i]).toFixed(1)},${fy(ys[i]).toFixed(1)}`);
    }
    return out;
  }

  function renderChart(mission, mapAnswer) {
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

  async function updateSweep(mission) {
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

  // ---------------------------------------------------------------- plan to fly

  // The sorties' colours on the map and in the table (none of them the battery scale's greens
  // and reds of the route underneath).
  const SORTIE_COLOURS = ['#1f5fbf', '#8e24aa', '#ef6c00', '#00838f', '#c2185b', '#5d4037', '#3949ab', '#9e9d24'];
  const sortieColour = (k) => SORTIE_COLOURS[k % SORTIE_COLOURS.length];

  function mmss(s) {
    if (typeof s !== 'number' || !Number.isFinite(s)) return '–';
    const total = Math.round(Math.max(0, s));
    return `${Math.floor(total / 60)}:${String(total % 60).padStart(2, '0')}`;
  }

  // The plan's options: the page's controls (no scenarios: a plan has none) and the panel's own.
  function flyOptions() {
    const q = options();
    q.delete('samples');
    const add = (key, id) => {
      const v = $(id).value.trim();
      if (v !== '') q.set(key, v);
    };
    add('speeds', '#fly-speeds');
    add('overlap_m', '#fly-overlap');
    add('max_speed', '#fly-max-speed');
    return q;
  }

  // Forget the plan shown (the mission or its conditions changed): its layers, its links.
  function clearFly(note) {
    state.flySeq += 1;
    for (const url of state.flyUrls) URL.revokeObjectURL(url);
    state.flyUrls = [];
    if (state.flyLayer) state.flyLayer.clearLayers();
    $('#map').classList.remove('flying');
    $('#fly-title').textContent = '';
    const box = $('#fly');
    box.dataset.state = 'none';
    delete box.dataset.batteries;
    box.replaceChildren(el('p', { class: 'muted', text: note || 'The files to upload, one per battery, for this mission in these conditions.' }));
  }

  async function planToFly() {
    const entry = state.current;
    if (!entry || entry.key === 'none') {
      showError('Plan to fly: no mission selected');
      return;
    }
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
    const children = [flyFigures(plan), flySorties(plan)];
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

  // One row per sortie, in its map colour.
  function flySorties(plan) {
    const heads = [['#', ''], ['File', ''], ['Items', ''], ['Energy', 'Wh'], ['Time', 'min:s'], ['Landing', '%'], ['No return', 'min:s']];
    const head = el('tr', {}, heads.map(headCell));
    const rows = plan.sorties.map((s, k) => {
      let items = s.first_item !== undefined ? `${s.first_item}–${s.last_item}` : '–';
      const inside = typeof s.ends_inside_leg_fraction === 'number';
      if (inside) items += '*';
      const tr = el('tr', {
        'data-sortie': String(k + 1),
        'data-file': s.file,
        'data-energy-wh': String(s.energy_wh),
        'data-duration-s': String(s.duration_s),
        'data-end-soc': String(s.end_soc),
      }, [
        el('td', { class: 'n' }, [el('span', { class: 'swatch', style: `background:${sortieColour(k)}` }), String(k + 1)]),
        el('td', { class: 'file', text: s.file }),
        el('td', { class: 'n', text: items }),
        el('td', { class: 'n', text: fmt(s.energy_wh, 1) }),
        el('td', { class: 'n', text: mmss(s.duration_s) }),
        el('td', { class: 'n', text: pct(s.end_soc) }),
        el('td', { class: 'n', text: typeof s.point_of_no_return_s === 'number' ? mmss(s.point_of_no_return_s) : 'none' }),
      ]);
      if (inside) tr.title = `turns home ${fmt(s.ends_inside_leg_fraction * 100, 0)} % of the way along the leg to item ${s.last_item}`;
      tr.addEventListener('mouseenter', () => lightSortie(k, true));
      tr.addEventListener('mouseleave', () => lightSortie(k, false));
      return tr;
    });
    const key = el('p', { class: 'fly-key muted', text: 'On the map: each sortie in its colour, the route solid, the way out dashed, the way home dotted; * turns home inside a leg.' });
    return el('div', {}, [el('div', { class: 'table-wrap' }, [el('table', { class: 'fly fly-sorties' }, [el('thead', {}, [head]), el('tbody', {}, rows)])]), key]);
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
    if (c.cut_inside_legs) lines.push(el('li', { text: 'sorties end inside legs (*), where each pack reaches the reserve' }));
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
        const tip = tipNode(`sortie ${k + 1} (${m.file}) · ${part.replace('_', ' ')}`, `${fmt(s.energy_wh, 1)} Wh · ${mmss(s.duration_s)} · lands at ${pct(s.end_soc)} %`);
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
    $('#map').classList.add('flying');
    const bounds = state.flyLayer.getBounds();
    if (bounds.isValid()) state.map.fitBounds(bounds, { padding: [30, 30], maxZoom: geo ? 19 : 4 });
  }

  function lightSortie(k, on) {
    for (const line of (state.flyLines || [])[k] || []) {
      line.setStyle({ weight: on ? 7 : line.options.className.includes('fly-route') ? 4 : 3 });
      if (on) line.bringToFront();
    }
    const tr = document.querySelector(`#fly tr[data-sortie="${k + 1}"]`);
    if (tr) tr.classList.toggle('highlight', on);
  }

  // A zip of text files, stored (no compression): the files of a plan in one download.
  function zipStored(files) {
    const enc = new TextEncoder();
    const table = crcTable();
    const crc32 = (bytes) => {
      let c = 0xffffffff;
      for (const b of bytes) c = table[(c ^ b) & 0xff] ^ (c >>> 8);
      return (c ^ 0xffffffff) >>> 0;
    };
    const now = new Date();
    const time = (now.getHours() << 11) | (now.getMinutes() << 5) | (now.getSeconds() >> 1);
    const date = ((now.getFullYear() - 1980) << 9) | ((now.getMonth() + 1) << 5) | now.getDate();
    const parts = [];
    const central = [];
    let offset = 0;
    for (const f of files) {
      const name = enc.encode(f.name);
      const data = enc.encode(f.text);
      const crc = crc32(data);
      // version 2.0, flags: names in UTF-8 (bit 11), stored
      const common = [[20, 2], [0x0800, 2], [0, 2], [time, 2], [date, 2], [crc, 4], [data.length, 4], [data.length, 4], [name.length, 2], [0, 2]];
      const local = le([[0x04034b50, 4], ...common]);
      parts.push(local, name, data);
      central.push(le([[0x02014b50, 4], [20, 2], ...common, [0, 2], [0, 2], [0, 2], [0, 4], [offset, 4]]), name);
      offset += local.length + name.length + data.length;
    }
    const size = central.reduce((n, p) => n + p.length, 0);
    const end = le([[0x06054b50, 4], [0, 2], [0, 2], [files.length, 2], [files.length, 2], [size, 4], [offset, 4], [0, 2]]);
    return new Blob([...parts, ...central, end], { type: 'application/zip' });
  }

  // Little-endian fields [value, bytes].
  function le(fields) {
    const out = new Uint8Array(fields.reduce((n, [, w]) => n + w, 0));
    let at = 0;
    for (const [v, w] of fields) {
      for (let i = 0; i < w; i++) out[at + i] = (v >>> (8 * i)) & 0xff;
      at += w;
    }
    return out;
  }

  let crcCache = null;
  function crcTable() {
    if (crcCache) return crcCache;
    crcCache = new Uint32Array(256);
    for (let n = 0; n < 256; n++) {
      let c = n;
      for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
      crcCache[n] = c >>> 0;
    }
    return crcCache;
  }

  // ---------------------------------------------------------------- vehicles

  // The server's vehicles (built-in, given, sent), its default (the first --vehicle) chosen.
  function fillVehicles() {
    const select = $('#vehicle');
    select.replaceChildren(...state.vehicles.map((v) => el('option', { value: v.name, text: v.name, title: v.description })));
    const chosen = state.config.default_vehicle;
    if (chosen && state.vehicles.some((v) => v.name === chosen)) select.value = chosen;
  }

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

  // The battery list follows the chosen vehicle (or the answer's vehicle when on the default).
  function syncBatteries(mission) {
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

  // ---------------------------------------------------------------- logs

  function renderLogInfo(info, name) {
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

  async function openFiles(files) {
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

  // ---------------------------------------------------------------- live

  function startLive() {
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

  function drawLive(u) {
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

  // ---------------------------------------------------------------- wiring

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


  // ---------------------------------------------------------------- logbook

  // The logbook's lists (`/api/logbook/vehicles`, `/api/logbook/packs`).
  const logbook = { vehicles: [], packs: [] };

  // A history chart: each series its own line through its points and a dot on each (a line never
  // joins two series: two packs are two lines), x the flight's place in the series' own flights
  // (1, 2, ...); a legend names the series. A series is coloured by its class, or by `colour`.
  function historyChart(container, label, yLabel, series) {
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
  function followInLogbook() {
    if (!logbook.vehicles.length) return;
    const flown = String($('#vehicle').value).trim().toLowerCase();
    const i = logbook.vehicles.findIndex((v) => String(v.key).trim().toLowerCase() === flown);
    if (i >= 0) showLogbookVehicle(i);
  }

  async function loadLogbook() {
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
})();
