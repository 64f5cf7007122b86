// Numbers, times, distances and names as the page shows them, and the page's colours.

// A name to save a file under: its last path component (whatever the server says), without
// control characters, `..` or a leading dot; `fallback` when nothing is left.
export function safeFileName(name, fallback) {
  const base = String(name === undefined || name === null ? '' : name).split(/[\\/]/).pop();
  const clean = base
    .replace(/[\u0000-\u001f\u007f:*?"<>|]/g, '_')
    .replace(/\.{2,}/g, '.')
    .replace(/^[.\s]+/, '')
    .trim();
  return clean || fallback;
}

// Names made unique in their order (`name (2).ext` for a second `name.ext`).
export function uniqueNames(names) {
  const seen = new Set();
  return names.map((n) => {
    let out = n;
    for (let k = 2; seen.has(out); k++) out = n.replace(/(\.[^.]*)?$/, (ext) => ` (${k})${ext}`);
    seen.add(out);
    return out;
  });
}

export function fmt(x, digits) {
  if (typeof x !== 'number' || !Number.isFinite(x)) return '–';
  return x.toLocaleString('en-US', { minimumFractionDigits: digits, maximumFractionDigits: digits });
}

export function pct(soc, digits) {
  return typeof soc === 'number' ? fmt(soc * 100, digits === undefined ? 1 : digits) : '–';
}

export function duration(s) {
  if (typeof s !== 'number' || !Number.isFinite(s)) return '–';
  const total = Math.round(s);
  const m = Math.floor(total / 60);
  const sec = total % 60;
  return m > 0 ? `${m} min ${String(sec).padStart(2, '0')} s` : `${sec} s`;
}

export function distance(m) {
  if (typeof m !== 'number') return '–';
  return m >= 1000 ? `${fmt(m / 1000, 2)} km` : `${fmt(m, 0)} m`;
}

export function basename(path) {
  return String(path).split(/[\\/]/).pop();
}

// Colour of a state of charge: green at full, amber half-way to the reserve, red at the reserve.
export function socColour(soc, reserve) {
  const r = typeof reserve === 'number' ? reserve : 0.2;
  if (typeof soc !== 'number') return '#777';
  if (soc < r) return '#8b0000';
  const f = Math.max(0, Math.min(1, (soc - r) / Math.max(1e-9, 1 - r)));
  // red (0) -> amber (0.5) -> green (1), in HSL hue 0..130
  const hue = Math.round(f * 130);
  return `hsl(${hue}, 75%, 40%)`;
}

// The sorties' colours on the map and in the table (none of them the battery scale's greens
// and reds of the route underneath).
export const SORTIE_COLOURS = ['#1f5fbf', '#8e24aa', '#ef6c00', '#00838f', '#c2185b', '#5d4037', '#3949ab', '#9e9d24'];
export const sortieColour = (k) => SORTIE_COLOURS[k % SORTIE_COLOURS.length];

export function mmss(s) {
  if (typeof s !== 'number' || !Number.isFinite(s)) return '–';
  const total = Math.round(Math.max(0, s));
  return `${Math.floor(total / 60)}:${String(total % 60).padStart(2, '0')}`;
}
