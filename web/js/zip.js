// A zip of text files, stored (no compression): the files of a plan in one download.

// A zip of text files, stored (no compression): the files of a plan in one download.
export function zipStored(files) {
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
