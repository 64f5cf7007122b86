// What the page knows (the server's configuration and vehicles, the missions listed, the map's
// layers, the requests in flight), and the page's controls as a request's options.

export const $ = (sel) => document.querySelector(sel);
export const body = document.body;

export const state = {
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

export function options() {
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
