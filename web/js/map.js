// The map (Leaflet): the route coloured by the battery left at each leg's end, home, the ends of
// sorties and the point of no return; a leg lit with its row of the segments table.

import { $, state } from './state.js';
import { el, escaped, tipNode } from './dom.js';
import { duration, fmt, pct, socColour } from './format.js';
import { drawLive } from './live.js';

export function highlight(index, on) {
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

export function ensureMap(geo) {
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

export function renderMap(mission, mapAnswer) {
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
