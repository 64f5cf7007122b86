// Elements built as text: every value from a file, a request or the server goes into the page
// through text nodes, `textContent` and attributes (`el`, `svg`), Leaflet's tooltips as nodes
// (`tipNode`), never a string (Leaflet parses a string as markup); the one place a library takes
// markup and no node (the tile layer's attribution) gets escaped text (`escaped`).

const SVG_NS = 'http://www.w3.org/2000/svg';

export function el(tag, attrs, children) {
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

export function svg(tag, attrs, text) {
  const e = document.createElementNS(SVG_NS, tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v !== undefined && v !== null) e.setAttribute(k, String(v));
  }
  if (text !== undefined) e.textContent = text;
  return e;
}

// A tooltip's content: its lines as text nodes (Leaflet puts a node in as it is, where it
// would parse a string as markup).
export function tipNode(...lines) {
  const box = el('div', { class: 'tip' });
  lines.forEach((line, k) => {
    if (k) box.append(el('br'));
    box.append(String(line));
  });
  return box;
}

// `text` with the characters of markup escaped, for the one place a library takes markup and
// no node (the tile layer's attribution).
export function escaped(text) {
  return String(text).replace(/[&<>"']/g, (c) => `&#${c.charCodeAt(0)};`);
}
