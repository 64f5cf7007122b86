// Real-browser tests of the `aloft serve` page: Debian chromium driven by playwright-core.
//
//   cd tests/browser && npm install && node run.mjs
//
// Environment: ALOFT_BIN (default ../../target/debug/aloft), ALOFT_DATA_DIR (default
// ../../../shared/data, i.e. `shared/data` next to the repository), CHROMIUM (default
// /usr/bin/chromium), UPDATE_SCREENSHOT=1 to rewrite docs/img/serve.png.
// Prints one `ok - ...` / `not ok - ...` line per check and exits 0 only when all pass.

import { spawn, execFileSync } from 'node:child_process';
import { readFileSync, readdirSync, mkdirSync, existsSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '../..');
const BIN = path.resolve(process.env.ALOFT_BIN || path.join(repo, 'target/debug/aloft'));
const DATA = path.resolve(process.env.ALOFT_DATA_DIR || path.resolve(here, '../../../shared/data'));
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const SHOTS = path.join(repo, 'target/browser');
const DEMO = path.join(repo, 'fixtures/missions/demo-survey.toml');
const LOG = path.join(DATA, 'flight_logs/px4_esc_status_log.ulg');
const DROP_MISSION = path.join(DATA, 'missions/kasperg3_mission.plan');
const PLAN_MISSION = path.join(DATA, 'missions/neilvaltec_test.plan');
const PLAN_WAYPOINTS = path.join(DATA, 'missions/brucdeng_aircart_mission.waypoints');
const TLOG = path.join(DATA, 'telemetry/ayoub_auto_mission_sitl.tlog');
const TERRAIN = path.join(DATA, 'terrain');
const RIDGE = path.join(repo, 'fixtures/missions/ridge-44n.toml');
const MISSION_EXT = /\.(plan|waypoints|toml|json|txt)$/i;
const started = Date.now();

// ------------------------------------------------------------------ reporting

let passed = 0;
let failed = 0;
function ok(name) {
  passed += 1;
  console.log(`ok - ${name}`);
}
function notOk(name, why) {
  failed += 1;
  console.log(`not ok - ${name}`);
  for (const line of String(why).split('\n')) console.log(`#   ${line}`);
}
async function check(name, fn) {
  try {
    const r = await fn();
    if (r === false) notOk(name, 'failed');
    else ok(name);
  } catch (e) {
    notOk(name, e && e.stack ? e.stack.split('\n').slice(0, 4).join('\n') : e);
  }
}
function assert(cond, message) {
  if (!cond) throw new Error(message);
}

// ------------------------------------------------------------------ servers

const servers = new Set();
function killAll() {
  for (const child of servers) {
    try {
      child.kill('SIGTERM');
    } catch (e) {
      /* already gone */
    }
  }
  servers.clear();
}
process.on('exit', killAll);
for (const sig of ['SIGINT', 'SIGTERM']) {
  process.on(sig, () => {
    killAll();
    process.exit(130);
  });
}

function serve(args) {
  return new Promise((resolve, reject) => {
    const child = spawn(BIN, ['serve', ...args, '--listen', '127.0.0.1:0'], { stdio: ['ignore', 'pipe', 'pipe'] });
    servers.add(child);
    let out = '';
    let err = '';
    const timer = setTimeout(() => {
      reject(new Error(`aloft serve did not print its URL in 15 s: ${out} ${err}`));
    }, 15000);
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) {
        clearTimeout(timer);
        resolve({ url: m[0], child, stop: () => stop(child) });
      }
    });
    child.stderr.on('data', (d) => {
      err += d;
    });
    child.on('exit', (code) => {
      servers.delete(child);
      clearTimeout(timer);
      reject(new Error(`aloft serve exited (${code}): ${err.trim()}`));
    });
    child.on('error', (e) => {
      clearTimeout(timer);
      reject(e);
    });
  });
}

function stop(child) {
  servers.delete(child);
  try {
    child.kill('SIGTERM');
  } catch (e) {
    /* gone */
  }
}

// ------------------------------------------------------------------ the CLI

// `aloft mission [FILE] ARGS --format json`: {status, json, message}; exit 1 is still an answer.
// With `cwd`, FILE is given relative to it (as a browser names an upload: by its base name).
function cliMission(file, args = [], cwd = undefined) {
  const argv = ['mission', ...(file ? [file] : []), ...args, '--format', 'json'];
  try {
    const stdout = execFileSync(BIN, argv, { cwd, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], maxBuffer: 1 << 28 });
    return { status: 0, json: JSON.parse(stdout) };
  } catch (e) {
    if (e.status === 1 && e.stdout) return { status: 1, json: JSON.parse(e.stdout) };
    const stderr = String(e.stderr || '');
    const line = stderr.split('\n').find((l) => l.startsWith('aloft: error: ')) || stderr.trim().split('\n').pop() || '';
    return { status: e.status, message: line.replace(/^aloft: error: /, '').trim() };
  }
}

// `aloft plan FILE ARGS -o DIR --force --format json`: {status, json}; exit 1 (no plan) is an answer.
function cliPlan(file, args, dir) {
  const argv = ['plan', file, ...args, '-o', dir, '--force', '--format', 'json'];
  try {
    return { status: 0, json: JSON.parse(execFileSync(BIN, argv, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] })) };
  } catch (e) {
    if (e.status === 1 && e.stdout) return { status: 1, json: JSON.parse(e.stdout) };
    throw new Error(`aloft ${argv.join(' ')}: exit ${e.status}: ${e.stderr}`);
  }
}

// The mission items of a written file as QGroundControl lists them, read from its text alone:
// [{seq, command, lat, lon}], numbered in order from 1 (0 is the planned home: a `.plan`'s
// `plannedHomePosition`, a `.waypoints` file's first row), a survey's items counted one by one.
function fileItems(file) {
  const text = readFileSync(file, 'utf8');
  if (file.endsWith('.plan')) {
    const flat = [];
    for (const it of JSON.parse(text).mission.items) {
      if (it.type === 'SimpleItem') flat.push(it);
      else for (const sub of it.TransectStyleComplexItem.Items) flat.push(sub);
    }
    return flat.map((it, k) => ({ seq: k + 1, command: it.command, lat: it.params[4], lon: it.params[5] }));
  }
  const rows = text.trim().split('\n').slice(1).map((l) => l.trim().split(/\s+/).map(Number));
  return rows.slice(1).map((r, k) => ({ seq: k + 1, command: r[3], lat: r[8], lon: r[9] }));
}

// Where a written sortie turns home (its last NAV_WAYPOINT before its RTL) and where it resumes
// the route (its first NAV_WAYPOINT after its take-off), from the file's items.
function turnsHome(items) {
  const rtl = items.findIndex((it) => it.command === 20);
  const before = (rtl < 0 ? items : items.slice(0, rtl)).filter((it) => it.command === 16);
  return before[before.length - 1];
}
function resumes(items) {
  const takeoff = items.findIndex((it) => it.command === 22);
  return items.slice(takeoff + 1).find((it) => it.command === 16);
}

// The sorties' table of the page: one object per row, the cells by their class.
async function flyRows(page) {
  return page.$$eval('#fly table.fly-sorties tbody tr', (trs) =>
    trs.map((tr) => {
      const cell = (cls) => {
        const td = tr.querySelector(`td.${cls}`);
        return td ? td.textContent : null;
      };
      return {
        file: tr.dataset.file,
        energy: tr.dataset.energyWh,
        soc: tr.dataset.endSoc,
        fileItems: cell('file-items'),
        missionItems: cell('mission-items'),
        band: cell('band'),
        share: cell('p-reserve'),
        text: tr.textContent,
      };
    }),
  );
}

// The page's answer settled: no plan to fly in flight, no re-plan pending or in flight.
async function flySettled(page, timeout = 60000) {
  await page.waitForFunction(
    () => !document.querySelector('#plan-fly').disabled && document.body.dataset.state !== 'loading' && document.querySelector('#fly').dataset.state !== 'loading',
    null,
    { timeout },
  );
  // a re-plan debounced after the answer (250 ms) would still forget it
  await new Promise((r) => setTimeout(r, 600));
  await page.waitForFunction(() => document.body.dataset.state !== 'loading', null, { timeout });
}

const percent1 = (x) => (100 * x).toFixed(1);

// A zip read by Python's zipfile: argv zip, then the files it should hold in order.
const ZIP_READER = `
import json, sys, zipfile, os
z = zipfile.ZipFile(sys.argv[1])
files = sys.argv[2:]
names = z.namelist()
same = names == [os.path.basename(f) for f in files] and all(z.read(n) == open(f, 'rb').read() for n, f in zip(names, files))
print(json.dumps({'bad': z.testzip(), 'names': names, 'same': same}))
`;

function cliLogInfo(file) {
  return JSON.parse(execFileSync(BIN, ['log', 'info', file, '--format', 'json'], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] }));
}

const expectedRows = (json) =>
  json.segments.map((s) => ({
    index: String(s.index),
    item: s.item === undefined || s.item === null ? null : String(s.item),
    kind: s.kind,
    energy: String(s.energy_wh),
    soc: String(s.end_soc),
  }));

async function pageRows(page) {
  return page.$$eval('#segments tbody tr', (trs) =>
    trs.map((tr) => ({
      index: tr.getAttribute('data-index'),
      item: tr.getAttribute('data-item'),
      kind: tr.getAttribute('data-kind'),
      energy: tr.getAttribute('data-energy-wh'),
      soc: tr.getAttribute('data-end-soc'),
    })),
  );
}

function compareRows(actual, expected) {
  assert(actual.length === expected.length, `${actual.length} rows in the page, ${expected.length} segments from the CLI`);
  for (let i = 0; i < expected.length; i++) {
    for (const k of Object.keys(expected[i])) {
      assert(actual[i][k] === expected[i][k], `row ${i} ${k}: page ${actual[i][k]} vs CLI ${expected[i][k]}`);
    }
  }
}

// ------------------------------------------------------------------ the page

const pageProblems = [];
const HTTP_4XX = /^Failed to load resource: the server responded with a status of 4\d\d /;
let expectRefusal = 0;
let expectedRefusals = 0;
// Run `fn` while a 4xx answer (and Chromium's console line about it) is expected.
async function refusing(fn) {
  expectRefusal += 1;
  try {
    return await fn();
  } finally {
    await new Promise((r) => setTimeout(r, 50));
    expectRefusal -= 1;
  }
}
let browser;

// Dialogs any page opened (an `alert` of injected markup): none is expected.
const dialogs = [];

async function openPage(url, viewport = { width: 1400, height: 900 }) {
  const context = await browser.newContext({ viewport, acceptDownloads: true });
  // Every Content-Security-Policy violation of the page, kept where a check can read it (the
  // listener is installed by the browser, so the page's policy does not apply to it).
  await context.addInitScript(() => {
    window.__violations = [];
    document.addEventListener('securitypolicyviolation', (e) => {
      window.__violations.push(`${e.violatedDirective} ${e.blockedURI} ${e.sample || ''}`.trim());
    });
  });
  const page = await context.newPage();
  page.on('dialog', (d) => {
    dialogs.push(`${url}: ${d.type()} ${d.message()}`);
    d.dismiss().catch(() => {});
  });
  page.on('pageerror', (e) => pageProblems.push(`pageerror at ${url}: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() !== 'error') return;
    // Chromium itself logs every 4xx answer to fetch() as a console error; those are expected
    // (and only those) while a check provokes a refusal.
    if (expectRefusal > 0 && HTTP_4XX.test(m.text())) expectedRefusals += 1;
    else pageProblems.push(`console error at ${url}: ${m.text()}`);
  });
  await page.goto(url);
  await waitReady(page, 0);
  return page;
}

// Wait until the page completed more than `before` re-plans and nothing is in flight.
async function waitReady(page, before, timeout = 20000) {
  await page.waitForFunction(
    (b) => Number(document.body.dataset.plans) > b && document.body.dataset.state !== 'loading',
    before,
    { timeout },
  );
}

const plans = (page) => page.evaluate(() => Number(document.body.dataset.plans));

async function shot(page, name) {
  mkdirSync(SHOTS, { recursive: true });
  await page.screenshot({ path: path.join(SHOTS, `${name}.png`) });
}

async function mapAnswer(base, file, text) {
  const url = new URL('api/map', base);
  if (file) url.searchParams.set('file', file);
  const r = await fetch(url, { method: 'POST', body: text });
  return r.json();
}

// Drop files (name + bytes) on the page with a real DataTransfer.
async function dropFiles(page, files) {
  const payload = files.map((f) => ({ name: f.name, b64: Buffer.from(f.bytes).toString('base64') }));
  const dt = await page.evaluateHandle((items) => {
    const transfer = new DataTransfer();
    for (const it of items) {
      const bin = atob(it.b64);
      const bytes = new Uint8Array(bin.length);
      for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
      transfer.items.add(new File([bytes], it.name));
    }
    return transfer;
  }, payload);
  await page.dispatchEvent('#map', 'dragenter', { dataTransfer: dt });
  await page.dispatchEvent('#map', 'dragover', { dataTransfer: dt });
  await page.dispatchEvent('#map', 'drop', { dataTransfer: dt });
}

async function setOptions(page, values) {
  await page.evaluate((vals) => {
    for (const [id, v] of Object.entries(vals)) {
      const input = document.getElementById(id);
      input.value = v;
      input.dispatchEvent(new Event('input', { bubbles: true }));
    }
  }, values);
}

// ------------------------------------------------------------------ the checks

async function main() {
  assert(existsSync(BIN), `no aloft binary at ${BIN} (set ALOFT_BIN)`);
  assert(existsSync(DATA), `no shared data at ${DATA} (set ALOFT_DATA_DIR)`);
  const missions = readdirSync(path.join(DATA, 'missions'))
    .filter((f) => f !== 'README.md' && MISSION_EXT.test(f))
    .sort()
    .map((f) => path.join(DATA, 'missions', f));
  browser = await chromium.launch({
    executablePath: CHROMIUM,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  // One section alone, while working on it: ALOFT_BROWSER_ONLY=markup, =logbook, =fly or =terrain.
  const only = { markup: markupEverywhere, logbook: logbookPanel, fly: planToFlyPanel, terrain: terrainProfile }[process.env.ALOFT_BROWSER_ONLY];
  if (only) {
    await only();
    await noProblems();
    return;
  }

  // --- 1, 2: every shared mission and the demo against the CLI. `aloft serve` refuses to start
  // with a mission it cannot fly, so the accepted ones are given on its command line (picked in
  // #mission-select) and the refused ones are opened with the #file input.
  const accepted = missions.filter((m) => cliMission(m).status <= 1);
  const refused = missions.filter((m) => !accepted.includes(m));
  const main = await serve([DEMO, ...accepted, LOG]);
  try {
    const page = await openPage(main.url);
    const config = await page.evaluate(() => fetch('/api/config').then((r) => r.json()));
    const given = config.files.filter((f) => f.kind === 'mission');
    await check(`the page lists the demo and the ${given.length} given missions`, async () => {
      const values = await page.$$eval('#mission-select option', (os) => os.map((o) => o.value));
      assert(values.length === given.length + 1, `${values.length} options`);
      assert(given.length === accepted.length + 1, `${given.length} missions in /api/config`);
    });
    await check('a given log shows its info in #log', async () => {
      const cli = cliLogInfo(LOG);
      await page.waitForSelector('#log .log-card', { timeout: 10000 });
      const card = await page.$eval('#log .log-card', (c) => ({ format: c.dataset.format, samples: c.dataset.samples, text: c.textContent }));
      assert(card.format === cli.format && card.samples === String(cli.samples), JSON.stringify(card));
    });
    const entries = [{ key: 'demo', file: null, label: 'built-in demo' }]
      .concat(given.map((f) => ({ key: `file:${f.index}`, file: f.name, label: path.basename(f.name) })))
      .concat(refused.map((f) => ({ upload: f, file: f, label: `${path.basename(f)} (opened)` })));
    for (const entry of entries) {
      const cli = entry.upload
        ? cliMission(path.basename(entry.file), [], path.dirname(entry.file))
        : cliMission(entry.file);
      const open = async () => {
        const before = await plans(page);
        if (entry.upload) await page.setInputFiles('#file', entry.upload);
        else await page.selectOption('#mission-select', entry.key);
        await waitReady(page, before);
      };
      if (cli.status > 1) await refusing(open);
      else await open();
      if (cli.status === 0 || cli.status === 1) {
        await check(`${entry.label}: table equals aloft mission (${cli.json.segments.length} segments, ${cli.json.feasible ? 'feasible' : 'infeasible'})`, async () => {
          compareRows(await pageRows(page), expectedRows(cli.json));
          const s = await page.$eval('#summary', (e) => ({ f: e.dataset.feasible, e: e.dataset.energyWh }));
          assert(s.f === String(cli.json.feasible) && s.e === String(cli.json.energy_wh), `summary ${JSON.stringify(s)}`);
          assert(await page.$eval('#error', (e) => e.hidden), 'error banner shown');
        });
        await check(`${entry.label}: the map holds the route`, async () => {
          const text = entry.file ? readFileSync(entry.file) : '';
          const answer = await mapAnswer(main.url, entry.upload ? path.basename(entry.file) : entry.file, text);
          const withPoints = answer.segments.filter((s) => s.points_m.length > 0).length;
          const n = await page.$$eval('#map path.seg', (ps) => ps.length);
          assert(n === answer.segments.length && n === withPoints, `${n} paths, ${answer.segments.length} map segments`);
          const indexed = await page.$$eval('#map path.seg', (ps) => ps.map((p) => p.dataset.index).join(','));
          assert(indexed === answer.segments.map((s) => String(s.index)).join(','), `data-index ${indexed}`);
          const box = await page.$eval('#map svg', (s) => {
            const r = s.getBoundingClientRect();
            return [r.width, r.height];
          });
          assert(box[0] > 0 && box[1] > 0, `map svg ${box}`);
          if (answer.point_of_no_return) assert(await page.$('#map path.pnr'), 'no point-of-no-return marker');
        });
      } else {
        await check(`${entry.label}: refused (exit ${cli.status}) and #error shows the CLI's message`, async () => {
          const shown = await page.$eval('#error', (e) => (e.hidden ? null : e.textContent));
          assert(shown === cli.message, `page: ${shown}\nCLI: ${cli.message}`);
          assert((await page.$$('#segments tbody tr')).length === 0, 'stale rows');
          assert((await page.evaluate(() => document.body.dataset.state)) === 'error', 'state is not error');
        });
      }
    }
    await check('hovering a table row highlights its leg', async () => {
      const before = await plans(page);
      await page.selectOption('#mission-select', 'demo');
      await waitReady(page, before);
      await page.hover('#segments tbody tr:nth-child(3)');
      const index = await page.$eval('#segments tbody tr:nth-child(3)', (tr) => tr.dataset.index);
      const lit = await page.$eval(`#map path.seg[data-index="${index}"]`, (p) => p.classList.contains('highlight'));
      assert(lit, 'the path is not highlighted');
    });
    await shot(page, 'demo');

    // --- 3: the wind re-plans
    await check('wind 8 m/s from 270 re-plans and the table equals aloft mission --wind-speed 8 --wind-from 270', async () => {
      const before = await plans(page);
      await setOptions(page, { 'wind-speed': '8', 'wind-from': '270' });
      await waitReady(page, before);
      const cli = cliMission(null, ['--wind-speed', '8', '--wind-from', '270']);
      compareRows(await pageRows(page), expectedRows(cli.json));
      const still = cliMission(null);
      assert(String(cli.json.energy_wh) !== String(still.json.energy_wh), 'the wind changed nothing');
    });

    await check('elevation 2000 m at 30 °C re-plans and the table equals aloft mission --elevation-m 2000 --temperature-c 30', async () => {
      const before = await plans(page);
      await setOptions(page, { elevation: '2000', temperature: '30' });
      await waitReady(page, before);
      const args = ['--wind-speed', '8', '--wind-from', '270', '--elevation-m', '2000', '--temperature-c', '30'];
      const cli = cliMission(null, args);
      compareRows(await pageRows(page), expectedRows(cli.json));
      const air = await page.$eval('#summary', (e) => e.textContent);
      assert(air.includes(cli.json.air_density_kg_m3.toFixed(3)), `the summary does not show the density ${cli.json.air_density_kg_m3}`);
      const sea = cliMission(null, ['--wind-speed', '8', '--wind-from', '270']);
      assert(cli.json.energy_wh > sea.json.energy_wh, 'thin air cost no more energy');
      const b2 = await plans(page);
      await setOptions(page, { elevation: '', temperature: '' });
      await waitReady(page, b2);
    });

    // --- 5: samples draw the band
    await check('samples 50 draw the p5-p95 band and the dashed p50', async () => {
      const before = await plans(page);
      await setOptions(page, { samples: '50' });
      await waitReady(page, before, 60000);
      assert(await page.$('#chart svg polygon.band'), 'no band polygon');
      assert(await page.$('#chart svg polyline.p50'), 'no p50 line');
    });
    await shot(page, 'demo-wind-samples');
    await check('a refused option shows the server message and the page stays alive', async () => {
      const before = await plans(page);
      await refusing(async () => {
        await setOptions(page, { samples: '', payload: '-3' });
        await waitReady(page, before);
      });
      const shown = await page.$eval('#error', (e) => (e.hidden ? '' : e.textContent));
      assert(shown.length > 0, 'no error shown');
      const b2 = await plans(page);
      await setOptions(page, { payload: '' });
      await waitReady(page, b2);
      assert(await page.$eval('#error', (e) => e.hidden), 'the error stayed');
      assert((await page.$$('#segments tbody tr')).length > 0, 'no rows after recovery');
    });
    await check('a reserve of 80 % (wind 8 m/s from 270) splits the demo into sorties: their ends and the point of no return are marked', async () => {
      const before = await plans(page);
      await setOptions(page, { reserve: '80' });
      await waitReady(page, before);
      const cli = cliMission(null, ['--wind-speed', '8', '--wind-from', '270', '--reserve-percent', '80']);
      assert(cli.json.sorties && cli.json.sorties.length >= 2, 'the CLI gives no sorties');
      compareRows(await pageRows(page), expectedRows(cli.json));
      const ends = await page.$$('#map path.sortie-end');
      assert(ends.length === cli.json.sorties.length, `${ends.length} sortie ends, ${cli.json.sorties.length} sorties`);
      assert(await page.$('#map path.pnr'), 'no point-of-no-return marker');
      assert(await page.$('#map-legend'), 'no colour legend');
      await shot(page, 'sorties');
      const b2 = await plans(page);
      await setOptions(page, { reserve: '' });
      await waitReady(page, b2);
    });
    await check('the payload sweep is drawn', async () => {
      assert(await page.$('#sweep svg polyline.sweep-hover'), 'no hover line');
      assert(await page.$('#sweep svg polyline.sweep-max'), 'no max endurance line');
      mkdirSync(SHOTS, { recursive: true });
      await page.locator('#sweep').screenshot({ path: path.join(SHOTS, 'sweep.png') });
    });

    // --- 4: dropped files
    await check(`a dropped ${path.basename(DROP_MISSION)} loads and its table equals aloft mission`, async () => {
      await setOptions(page, { 'wind-speed': '', 'wind-from': '' });
      await page.waitForFunction(() => document.body.dataset.state !== 'loading');
      const before = await plans(page);
      await dropFiles(page, [{ name: path.basename(DROP_MISSION), bytes: readFileSync(DROP_MISSION) }]);
      await waitReady(page, before);
      const cli = cliMission(DROP_MISSION);
      compareRows(await pageRows(page), expectedRows(cli.json));
      const selected = await page.$eval('#mission-select', (s) => s.selectedOptions[0].textContent);
      assert(selected.includes(path.basename(DROP_MISSION)), `selected ${selected}`);
    });
    await check(`a dropped log (${path.basename(LOG)}) shows its format and samples in #log`, async () => {
      const cli = cliLogInfo(LOG);
      const name = `dropped-${path.basename(LOG)}`;
      await dropFiles(page, [{ name, bytes: readFileSync(LOG) }]);
      const sel = `#log .log-card[data-file="${name}"]`;
      await page.waitForSelector(sel, { timeout: 10000 });
      const card = await page.$eval(sel, (c) => ({ format: c.dataset.format, samples: c.dataset.samples, text: c.textContent }));
      assert(card.format === cli.format, `format ${card.format} vs ${cli.format}`);
      assert(card.samples === String(cli.samples), `samples ${card.samples} vs ${cli.samples}`);
      assert(card.text.includes(cli.format) && card.text.includes(String(cli.samples)), 'not visible');
      await page.locator('#log').screenshot({ path: path.join(SHOTS, 'log.png') });
    });
    await check('a dropped file the server cannot read shows its error', async () => {
      await refusing(async () => {
        await dropFiles(page, [{ name: 'garbage.bin', bytes: Buffer.from('not a flight log at all\n') }]);
        await page.waitForSelector('#error:not([hidden])', { timeout: 10000 });
      });
    });
    await check('a mission chosen with the #file input loads', async () => {
      const file = missions.find((m) => m.endsWith('.waypoints') && cliMission(m).status === 0);
      const before = await plans(page);
      await page.setInputFiles('#file', file);
      await waitReady(page, before);
      compareRows(await pageRows(page), expectedRows(cliMission(file).json));
    });
    await page.context().close();
  } finally {
    main.stop();
  }

  await planToFlyPanel();

  // --- the route's profile over the ground (aloft serve --terrain)
  await terrainProfile();

  // --- geographic map with a tile layer (tiles served by aloft itself: works offline)
  const geo = await serve([DROP_MISSION, '--tiles', '/vendor/leaflet/images/layers.png?{z}/{x}/{y}', '--attribution', 'test tiles']);
  try {
    const page = await openPage(geo.url);
    await check('with --tiles a mission with a home is drawn on a geographic map with tiles', async () => {
      const answer = await mapAnswer(geo.url, DROP_MISSION, readFileSync(DROP_MISSION));
      assert(answer.home, 'no home');
      const n = await page.$$eval('#map path.seg', (ps) => ps.length);
      assert(n === answer.segments.length, `${n} paths vs ${answer.segments.length}`);
      await page.waitForSelector('#map .leaflet-tile-pane img', { timeout: 10000 });
      const attribution = await page.$eval('#map .leaflet-control-attribution', (e) => e.textContent);
      assert(attribution.includes('test tiles'), attribution);
      assert(await page.$('#map path.home'), 'no home marker');
      await shot(page, 'geo');
    });
    await check('switching to the demo (no home) falls back to the plain metric map', async () => {
      const before = await plans(page);
      await page.selectOption('#mission-select', 'demo');
      await waitReady(page, before);
      assert(!(await page.$('#map .leaflet-tile-pane img')), 'tiles still shown');
      assert((await page.$$('#map path.seg')).length > 0, 'no route');
    });
    await page.context().close();
  } finally {
    geo.stop();
  }

  // --- 6: live telemetry
  const live = await serve(['--tlog', TLOG, '--speed', 'max']);
  try {
    const page = await openPage(live.url);
    await check(`live: #live shows updates from ${path.basename(TLOG)} and the vehicle marker`, async () => {
      await page.waitForFunction(() => document.querySelector('#live') && !document.querySelector('#live').hidden && document.querySelector('#live').dataset.mode, null, { timeout: 20000 });
      await page.waitForSelector('#map path.vehicle', { timeout: 10000 });
      const p = await page.$eval('#live', (e) => ({ mode: e.dataset.mode, advice: e.dataset.advice, text: e.textContent }));
      assert(p.mode.length > 0 && p.text.includes(p.mode), JSON.stringify(p));
      assert(p.text.includes('Wh'), 'no energy shown');
      // Once the estimate is made: the energy left with its band, and one of aloft live's advices.
      await page.waitForFunction(() => document.querySelector('#live').dataset.advice, null, { timeout: 90000 });
      const q = await page.$eval('#live', (e) => ({ advice: e.dataset.advice, text: e.textContent }));
      assert(['continue', 'return now', 'land now', 'do not take off'].includes(q.advice), `advice ${q.advice}`);
      assert(q.text.includes('Remaining') && q.text.includes(q.advice), q.text);
    });
    await shot(page, 'live');
    await page.context().close();
  } finally {
    live.stop();
  }

  // --- 8: the documentation screenshot (always to target/browser, docs/img with UPDATE_SCREENSHOT=1)
  const doc = await serve([]);
  try {
    const page = await openPage(doc.url, { width: 1400, height: 900 });
    await check('screenshot: the demo with wind 6 m/s from 270 and 100 samples', async () => {
      const before = await plans(page);
      await setOptions(page, { 'wind-speed': '6', 'wind-from': '270', samples: '100' });
      await waitReady(page, before, 60000);
      assert(await page.$('#chart svg polygon.band'), 'no band');
      await page.hover('#segments tbody tr:nth-child(6)');
      await page.mouse.move(5, 300);
      await page.waitForTimeout(300);
      await shot(page, 'serve');
      if (process.env.UPDATE_SCREENSHOT === '1') {
        await page.screenshot({ path: path.join(repo, 'docs/img/serve.png') });
      }
    });
    await page.context().close();
  } finally {
    doc.stop();
  }

  // --- 9: the logbook's histories
  await logbookPanel();
  const nobook = await serve([]);
  try {
    const page = await openPage(nobook.url);
    await check('without --logbook: no panel, and /api/logbook/vehicles is 404', async () => {
      assert(await page.$eval('#logbook-panel', (e) => e.hidden), 'panel shown');
      const status = await refusing(() => page.evaluate(() => fetch('/api/logbook/vehicles').then((r) => r.status)));
      assert(status === 404, `${status}`);
    });
    await page.context().close();
  } finally {
    nobook.stop();
  }

  // --- 10: your own vehicles: a vehicle file given with --vehicle (`aloft vehicles template`)
  // listed and chosen, the page's answers the command line's with that file; a vehicle file
  // dropped on the page (a built-in's file, renamed) added, chosen and flown.
  const vehDir = mkdtempSync(path.join(os.tmpdir(), 'aloft-vehicles-'));
  const myQuad = path.join(vehDir, 'my-quad.toml');
  writeFileSync(myQuad, execFileSync(BIN, ['vehicles', 'template'], { encoding: 'utf8' }));
  const inspire = readFileSync(path.join(repo, 'fixtures/vehicles/dji-inspire1.toml'), 'utf8');
  const dropped = path.join(vehDir, 'dropped-inspire.toml');
  writeFileSync(dropped, inspire.replace('name = "dji-inspire1"', 'name = "dropped-inspire"'));
  const own = await serve(['--vehicle', myQuad]);
  try {
    const page = await openPage(own.url);
    const summary = () => page.$eval('#summary', (e) => ({ f: e.dataset.feasible, e: e.dataset.energyWh, text: e.textContent }));
    const chosen = () => page.$eval('#vehicle', (s) => s.value);
    const listed = () => page.$$eval('#vehicle option', (os) => os.map((o) => o.value));
    await check('--vehicle my-quad.toml (aloft vehicles template): in the vehicle list and chosen by default', async () => {
      const names = await listed();
      assert(names.includes('my-quad') && names.includes('dji-m100'), names.join(','));
      assert((await chosen()) === 'my-quad', `chosen ${await chosen()}`);
    });
    await check('the demo flown with my-quad: the page shows aloft mission --vehicle my-quad.toml', async () => {
      const cli = cliMission(null, ['--vehicle', myQuad]);
      assert(cli.status <= 1 && cli.json.vehicle === 'my-quad', JSON.stringify(cli).slice(0, 200));
      compareRows(await pageRows(page), expectedRows(cli.json));
      const s = await summary();
      assert(s.f === String(cli.json.feasible) && s.e === String(cli.json.energy_wh), JSON.stringify(s));
      assert(s.text.includes('my-quad'), s.text);
    });
    await check("my-quad's packs in the battery list, its payload sweep drawn", async () => {
      const packs = await page.$$eval('#battery option', (os) => os.map((o) => o.value).filter((v) => v));
      assert(packs.join(',') === '3S-5000', packs.join(','));
      await page.waitForFunction(() => document.querySelector('#sweep-title').textContent.startsWith('my-quad'), null, { timeout: 10000 });
      assert(await page.$('#sweep svg polyline.sweep-hover'), 'no sweep');
    });
    const missionsBefore = await page.$$eval('#mission-select option', (os) => os.length);
    await check('a dropped vehicle file (dji-inspire1 renamed) is listed, chosen, and the page shows aloft mission --vehicle dropped-inspire.toml', async () => {
      const before = await plans(page);
      await dropFiles(page, [{ name: path.basename(dropped), bytes: readFileSync(dropped) }]);
      await waitReady(page, before);
      assert((await listed()).includes('dropped-inspire'), (await listed()).join(','));
      assert((await chosen()) === 'dropped-inspire', `chosen ${await chosen()}`);
      const cli = cliMission(null, ['--vehicle', dropped]);
      assert(cli.status <= 1 && cli.json.vehicle === 'dropped-inspire', JSON.stringify(cli).slice(0, 200));
      compareRows(await pageRows(page), expectedRows(cli.json));
      const s = await summary();
      assert(s.f === String(cli.json.feasible) && s.e === String(cli.json.energy_wh), JSON.stringify(s));
      const mine = cliMission(null, ['--vehicle', myQuad]);
      assert(s.e !== String(mine.json.energy_wh), 'the same energy as my-quad');
      const missions = await page.$$eval('#mission-select option', (os) => os.length);
      assert(missions === missionsBefore, `${missions} missions: taken as a mission`);
      const served = await page.evaluate(() => fetch('/api/vehicles').then((r) => r.json()));
      assert(served.some((v) => v.name === 'dropped-inspire' && v.batteries.length > 0), 'not in /api/vehicles');
    });
    await check('a dropped mission .toml stays a mission, flown with the chosen vehicle', async () => {
      const before = await plans(page);
      await dropFiles(page, [{ name: 'demo-copy.toml', bytes: readFileSync(DEMO) }]);
      await waitReady(page, before);
      const label = await page.$eval('#mission-select', (s) => s.selectedOptions[0].textContent);
      assert(label.includes('demo-copy.toml'), label);
      assert((await chosen()) === 'dropped-inspire', `chosen ${await chosen()}`);
      compareRows(await pageRows(page), expectedRows(cliMission(DEMO, ['--vehicle', dropped]).json));
    });
    await check("a dropped vehicle file named as a built-in is refused with the server's message", async () => {
      const clash = readFileSync(myQuad, 'utf8').replace('name = "my-quad"', 'name = "dji-m100"');
      const names = await listed();
      await refusing(async () => {
        await dropFiles(page, [{ name: 'clash.toml', bytes: Buffer.from(clash) }]);
        await page.waitForSelector('#error:not([hidden])', { timeout: 10000 });
      });
      const shown = await page.$eval('#error', (e) => e.textContent);
      assert(shown.includes('clash.toml') && shown.includes("'dji-m100' is a built-in vehicle's"), shown);
      assert((await listed()).join(',') === names.join(','), 'the list changed');
    });
    await page.context().close();
  } finally {
    own.stop();
    rmSync(vehDir, { recursive: true, force: true });
  }

  // --- 11: markup in every name, on every panel (issue 41)
  await markupEverywhere();

  // --- 7: no page errors anywhere
  await noProblems();
}

// --- 9: plan to fly: the files of `aloft plan`, drawn and offered on the page
async function planToFlyPanel() {
  const fly = await serve([PLAN_MISSION, PLAN_WAYPOINTS]);
  try {
    const page = await openPage(fly.url);
    const conditions = ['--reserve-percent', '70', '--wind-speed', '8', '--wind-from', '0'];
    const out = path.join(SHOTS, 'plan-to-fly-cli');
    const cli = cliPlan(PLAN_MISSION, conditions, out);
    const n = cli.json.sorties.length;
    const before = await plans(page);
    await setOptions(page, { reserve: '70', 'wind-speed': '8', 'wind-from': '0' });
    await waitReady(page, before);
    let seconds = NaN;
    await check(`plan to fly ${path.basename(PLAN_MISSION)} (reserve 70 %, wind 8 m/s from 0): the sorties' table equals aloft plan (${n} sorties)`, async () => {
      assert(n >= 2, `aloft plan gives ${n} sorties`);
      const t0 = Date.now();
      await page.click('#plan-fly');
      await page.waitForSelector('#fly[data-state="ready"] table.fly-sorties tbody tr', { timeout: 60000 });
      seconds = (Date.now() - t0) / 1000;
      const rows = await page.$$eval('#fly table.fly-sorties tbody tr', (trs) => trs.map((tr) => ({ file: tr.dataset.file, energy: tr.dataset.energyWh, soc: tr.dataset.endSoc, text: tr.textContent })));
      assert(rows.length === n, `${rows.length} rows`);
      cli.json.sorties.forEach((s, k) => {
        assert(rows[k].file === path.basename(s.file), `row ${k} file ${rows[k].file}`);
        assert(rows[k].energy === String(s.energy_wh) && rows[k].soc === String(s.end_soc), `row ${k}: ${JSON.stringify(rows[k])}`);
      });
      const figures = await page.$$eval('#fly table.fly-figures tbody tr', (trs) => trs.map((tr) => [...tr.cells].map((c) => c.textContent)));
      const mmss = (s) => `${Math.floor(Math.round(s) / 60)}:${String(Math.round(s) % 60).padStart(2, '0')}`;
      assert(figures[0][1] === String(cli.json.as_given.batteries) && figures[0][2] === mmss(cli.json.as_given.duration_s), `as given ${figures[0]}`);
      assert(figures[1][1] === String(n) && figures[1][2] === mmss(cli.json.duration_s), `plan ${figures[1]}`);
      assert(await page.$eval('#error', (e) => e.hidden), 'error banner shown');
      // What changed names each survey the plan turned, with the angles aloft plan gives.
      const changed = await page.$eval('#fly ul.fly-changes', (u) => u.textContent);
      const angles = cli.json.changes.angles || [];
      assert(angles.length >= 1, 'aloft plan turns the survey in this wind');
      for (const a of angles) {
        assert(changed.includes(`survey at item ${a.item} turned to the wind`) && changed.includes(`${Math.round(a.to_deg)}°`), changed);
      }
    });
    console.log(`# plan to fly: ${n} sorties of ${path.basename(PLAN_MISSION)} in ${seconds.toFixed(2)} s from the click to the table (target 3 s)`);
    await check('plan to fly: each sortie drawn in its own colour (way out, route, way home), the route behind', async () => {
      for (const part of ['fly-way-out', 'fly-route', 'fly-way-home']) {
        const count = await page.$$eval(`#map path.${part}`, (ps) => ps.length);
        assert(count === n, `${count} ${part} paths`);
      }
      const colours = await page.$$eval('#map path.fly-route', (ps) => ps.map((p) => p.getAttribute('stroke')));
      assert(new Set(colours).size === n, `colours ${colours}`);
      for (let k = 1; k <= n; k++) {
        const own = await page.$$eval(`#map path.fly-sortie-${k}`, (ps) => new Set(ps.map((p) => p.getAttribute('stroke'))).size);
        assert(own === 1, `sortie ${k} in ${own} colours`);
      }
      assert(await page.$eval('#map', (m) => m.classList.contains('flying')), 'the route is not set back');
    });
    await check(`plan to fly: where each sortie turns home and the next resumes, marked and labelled at the written files' waypoints (${n - 1} cuts)`, async () => {
      const marks = await page.$$eval('#map .fly-mark', (ms) =>
        ms.map((m) => ({ tag: m.tagName, kind: m.dataset.kind, sortie: m.dataset.sortie, lat: Number(m.dataset.latDeg), lon: Number(m.dataset.lonDeg) })),
      );
      const labels = await page.$$eval('#map .leaflet-tooltip.fly-mark-label', (ts) => ts.map((t) => t.textContent));
      const cuts = marks.filter((m) => m.kind === 'cut');
      const resumed = marks.filter((m) => m.kind === 'resume');
      assert(cuts.length === n - 1 && resumed.length === n - 1, `${cuts.length} cut and ${resumed.length} resume marks for ${n} sorties`);
      // markers of their own (the marker pane), none of them a path of the route or of a sortie
      assert(marks.every((m) => m.tag === 'DIV'), JSON.stringify(marks));
      assert(labels.length === 2 * (n - 1), `${labels.length} labels`);
      // The mark is where the flown path turns: within the waypoint's acceptance radius of the
      // file's waypoint (2 m, PX4's and ArduPilot's default, where a pass-through corner starts;
      // 0.5 m more for the turn's own curve), and nearer it than any other waypoint of the file.
      const metres = (a, b) => {
        const r = 6371000;
        const rad = Math.PI / 180;
        const x = (b.lon - a.lon) * rad * Math.cos(((a.lat + b.lat) / 2) * rad) * r;
        return Math.hypot(x, (b.lat - a.lat) * rad * r);
      };
      const near = (m, it, items) =>
        metres(m, it) <= 2.5 && items.filter((o) => o.command === 16 && o.seq !== it.seq).every((o) => metres(m, o) > metres(m, it));
      for (let k = 1; k < n; k++) {
        const s = cli.json.sorties[k - 1];
        const ownItems = fileItems(cli.json.files[k - 1]);
        const cut = turnsHome(ownItems);
        const mark = cuts.find((m) => m.sortie === String(k));
        assert(mark && near(mark, cut, ownItems), `sortie ${k} turns home at ${JSON.stringify(mark)}, its file at item ${cut.seq} ${cut.lat}, ${cut.lon}`);
        const home = labels.find((t) => t.startsWith(`sortie ${k} turns home`));
        assert(home && home.includes(`item ${cut.seq} of its file`), `label ${home} (file item ${cut.seq})`);
        if (typeof s.ends_inside_leg_fraction === 'number') {
          const along = `${Math.round(100 * s.ends_inside_leg_fraction)} % of the way to mission item ${s.last_item}`;
          assert(home.includes(along), `label ${home} lacks '${along}'`);
        }
        const nextItems = fileItems(cli.json.files[k]);
        const res = resumes(nextItems);
        const back = resumed.find((m) => m.sortie === String(k + 1));
        assert(back && near(back, res, nextItems), `sortie ${k + 1} resumes at ${JSON.stringify(back)}, its file at item ${res.seq} ${res.lat}, ${res.lon}`);
        const again = labels.find((t) => t.startsWith(`sortie ${k + 1} resumes`));
        assert(again && again.includes(`item ${res.seq} of its file`), `label ${again} (file item ${res.seq})`);
      }
    });
    await check("plan to fly: each sortie's items as its file numbers them (QGroundControl's), the mission's items it covers labelled as such", async () => {
      const heads = await page.$$eval('#fly table.fly-sorties thead th', (ths) => ths.map((th) => th.textContent));
      assert(heads.some((h) => h.startsWith('File items')) && heads.some((h) => h.startsWith('Mission items')), `heads ${heads}`);
      const rows = await flyRows(page);
      cli.json.sorties.forEach((s, k) => {
        const items = fileItems(cli.json.files[k]);
        const own = `${items[0].seq}–${items[items.length - 1].seq}`;
        assert(rows[k].fileItems === own, `sortie ${k + 1}: file items '${rows[k].fileItems}', its file has ${own}`);
        assert(rows[k].missionItems && rows[k].missionItems.startsWith(`${s.first_item}–${s.last_item}`), `sortie ${k + 1}: mission items '${rows[k].missionItems}'`);
      });
    });
    await check("plan to fly: each sortie's landing band (p5–p95) and share with the reserve, the plan's confidence and scenarios above the table", async () => {
      const rows = await flyRows(page);
      cli.json.sorties.forEach((s, k) => {
        const band = `${percent1(s.landing_soc.p5)}–${percent1(s.landing_soc.p95)}`;
        assert(rows[k].band === band, `sortie ${k + 1}: band '${rows[k].band}', aloft plan ${band}`);
        assert(rows[k].share === percent1(s.p_reserve), `sortie ${k + 1}: share '${rows[k].share}', aloft plan ${s.p_reserve}`);
      });
      const line = await page.$eval('#fly p.fly-confidence', (p) => p.textContent);
      const sc = cli.json.scenarios;
      const sp = sc.spreads;
      for (const part of [`${Number((100 * cli.json.confidence).toFixed(1))} % of ${sc.samples} scenarios`, `wind ${sp.wind_speed_sd_mps.toFixed(1)} m/s and ${Math.round(sp.wind_from_sd_deg)}°`, `capacity ${Math.round(sp.capacity_sd_percent)} %`, `power ${Math.round(sp.power_sd_percent)} %`]) {
        assert(line.includes(part), `'${line}' lacks '${part}'`);
      }
      const above = await page.$eval('#fly p.fly-confidence', (p) => Boolean(p.compareDocumentPosition(document.querySelector('#fly table.fly-sorties')) & Node.DOCUMENT_POSITION_FOLLOWING));
      assert(above, 'the line is not above the table');
    });
    await shot(page, 'plan-to-fly');
    await check('plan to fly: each file downloads as aloft plan writes it, and all of them in one zip', async () => {
      const links = await page.$$eval('#fly a.fly-file', (as) => as.map((a) => a.getAttribute('download')));
      assert(links.join(',') === cli.json.files.map((f) => path.basename(f)).join(','), `links ${links}`);
      for (let k = 0; k < n; k++) {
        const [download] = await Promise.all([page.waitForEvent('download'), page.click(`#fly a.fly-file >> nth=${k}`)]);
        const got = readFileSync(await download.path(), 'utf8');
        assert(download.suggestedFilename() === links[k], download.suggestedFilename());
        assert(got === readFileSync(cli.json.files[k], 'utf8'), `${links[k]} differs from the file aloft plan wrote`);
      }
      const [zip] = await Promise.all([page.waitForEvent('download'), page.click('#fly a.fly-all')]);
      const zipPath = path.join(SHOTS, zip.suggestedFilename());
      await zip.saveAs(zipPath);
      // Python's zipfile (CRCs checked by testzip) reads it: the same files, the same texts.
      const listed = JSON.parse(execFileSync('python3', ['-c', ZIP_READER, zipPath, ...cli.json.files], { encoding: 'utf8' }));
      assert(listed.bad === null && listed.names.join(',') === links.join(','), JSON.stringify(listed));
      assert(listed.same, 'a file in the zip differs from the file aloft plan wrote');
    });
    await check('plan to fly: the confidence control (0.5 to 0.999, default 0.95) is sent as confidence', async () => {
      const attrs = await page.$eval('#fly-confidence', (i) => ({ type: i.type, min: i.min, max: i.max, step: i.step, value: i.value }));
      assert(JSON.stringify(attrs) === JSON.stringify({ type: 'number', min: '0.5', max: '0.999', step: '0.01', value: '0.95' }), JSON.stringify(attrs));
      const half = cliPlan(PLAN_MISSION, [...conditions, '--confidence', '0.5'], path.join(SHOTS, 'plan-to-fly-half'));
      const energies = (j) => j.sorties.map((s) => String(s.energy_wh)).join(',');
      assert(energies(half.json) !== energies(cli.json), 'aloft plan cuts the same at 0.5 and 0.95: the check could not tell');
      await page.fill('#fly-confidence', '0.5');
      await page.click('#plan-fly');
      await flySettled(page);
      assert((await page.$eval('#fly', (e) => e.dataset.state)) === 'ready', 'no plan shown');
      const rows = await flyRows(page);
      assert(rows.map((r) => r.energy).join(',') === energies(half.json), `page ${rows.map((r) => r.energy)} vs aloft plan --confidence 0.5 ${energies(half.json)}`);
      const line = await page.$eval('#fly p.fly-confidence', (p) => p.textContent);
      assert(line.includes('50 % of'), line);
      await refusing(async () => {
        await page.fill('#fly-confidence', '0.3');
        await page.click('#plan-fly');
        await page.waitForSelector('#fly[data-state="error"]', { timeout: 60000 });
      });
      const shown = await page.$eval('#error', (e) => (e.hidden ? '' : e.textContent));
      assert(shown.startsWith('Plan to fly: ') && shown.includes('confidence'), shown);
      await page.fill('#fly-confidence', '0.95');
    });
    for (const [wind, how] of [['5', 'pressed right after typing the wind'], ['7', 'pressed once the typed wind is re-planned, the field still in focus']]) {
      await check(`plan to fly: ${how}, it plans with the wind typed (${wind} m/s) and keeps the plan`, async () => {
        const typed = cliPlan(PLAN_MISSION, ['--reserve-percent', '70', '--wind-speed', wind, '--wind-from', '0'], path.join(SHOTS, `plan-to-fly-typed-${wind}`));
        const b = await plans(page);
        await page.fill('#wind-speed', wind);
        if (wind === '7') await waitReady(page, b);
        await page.click('#plan-fly');
        await flySettled(page);
        const state = await page.$eval('#fly', (e) => e.dataset.state);
        assert(state === 'ready', `the plan to fly is '${state}'`);
        const rows = await flyRows(page);
        const want = typed.json.sorties.map((s) => String(s.energy_wh)).join(',');
        assert(rows.map((r) => r.energy).join(',') === want, `page ${rows.map((r) => r.energy)} vs aloft plan at ${wind} m/s ${want}`);
      });
    }
    {
      const b = await plans(page);
      await setOptions(page, { 'wind-speed': '8' });
      await waitReady(page, b);
    }
    await check('plan to fly: changing the wind forgets the plan (its layers and its files)', async () => {
      const b = await plans(page);
      await setOptions(page, { 'wind-from': '90' });
      await waitReady(page, b);
      assert((await page.$$('#map path.fly')).length === 0, 'sortie paths left');
      assert((await page.$$('#fly a.fly-file')).length === 0, 'download links left');
      assert((await page.$eval('#fly', (e) => e.dataset.state)) === 'none', 'state');
    });
    await check('plan to fly: no plan at a 99 % reserve shows why, as aloft plan says it', async () => {
      const b = await plans(page);
      await setOptions(page, { reserve: '99', 'wind-from': '0' });
      await waitReady(page, b);
      const none = cliPlan(PLAN_MISSION, ['--reserve-percent', '99', '--wind-speed', '8', '--wind-from', '0'], path.join(SHOTS, 'plan-to-fly-none'));
      assert(none.status === 1 && none.json.feasible === false, `aloft plan exit ${none.status}`);
      await page.click('#plan-fly');
      await page.waitForSelector('#fly[data-state="infeasible"]', { timeout: 60000 });
      const text = await page.$eval('#fly', (e) => e.textContent);
      assert(text.includes(none.json.reason), text);
      assert((await page.$$('#map path.fly')).length === 0, 'sortie paths drawn');
    });
    await check('plan to fly: an option out of range shows the server message', async () => {
      const b = await plans(page);
      await setOptions(page, { reserve: '70' });
      await waitReady(page, b);
      await refusing(async () => {
        await page.fill('#fly-overlap', '-5');
        await page.click('#plan-fly');
        await page.waitForSelector('#fly[data-state="error"]', { timeout: 60000 });
      });
      const shown = await page.$eval('#error', (e) => (e.hidden ? '' : e.textContent));
      assert(shown.includes('overlap_m') && shown.startsWith('Plan to fly: '), shown);
      await page.fill('#fly-overlap', '');
    });
    await check(`plan to fly ${path.basename(PLAN_WAYPOINTS)}: the file items are its rows' (QGroundControl's), the mission's items labelled apart`, async () => {
      const wcli = cliPlan(PLAN_WAYPOINTS, conditions, path.join(SHOTS, 'plan-to-fly-waypoints'));
      const b = await plans(page);
      await page.selectOption('#mission-select', { label: path.basename(PLAN_WAYPOINTS) });
      await waitReady(page, b);
      await page.click('#plan-fly');
      await flySettled(page);
      const rows = await flyRows(page);
      assert(rows.length === wcli.json.sorties.length, `${rows.length} rows`);
      wcli.json.sorties.forEach((s, k) => {
        const items = fileItems(wcli.json.files[k]);
        const own = `${items[0].seq}–${items[items.length - 1].seq}`;
        assert(rows[k].fileItems === own, `sortie ${k + 1}: file items '${rows[k].fileItems}', its file has ${own}`);
        assert(rows[k].missionItems && rows[k].missionItems.startsWith(`${s.first_item}–${s.last_item}`), `mission items '${rows[k].missionItems}'`);
      });
    });
    await page.context().close();
  } finally {
    fly.stop();
  }

}

// --- 12: the route's profile over the ground (issue 45): served with --terrain, the ridge
// mission's profile chart under the map (the route's altitude, the ground filled), its least
// clearance labelled as `aloft mission --terrain` gives it; values with markup shown as text;
// hidden for a mission refused over the tiles and without terrain.
async function terrainProfile() {
  const cli = cliMission(RIDGE, ['--terrain', TERRAIN]);
  const server = await serve([RIDGE, '--terrain', TERRAIN]);
  const profileOf = (page) =>
    page.$eval('#profile', (c) => {
      const count = (sel) => {
        const e = c.querySelector(sel);
        return e ? e.getAttribute('points').trim().split(/\s+/).length : 0;
      };
      const label = c.querySelector('text.least-label');
      const box = c.getBoundingClientRect();
      return {
        hidden: document.querySelector('#profile-panel').hidden,
        points: c.dataset.points,
        ground: count('polygon.ground'),
        route: count('polyline.route-altitude'),
        label: label ? label.textContent : null,
        dot: Boolean(c.querySelector('circle.least-dot')),
        height: box.height,
        mapHeight: document.querySelector('#map').getBoundingClientRect().height,
      };
    });
  try {
    const page = await openPage(server.url);
    if ((await page.$eval('#mission-select', (s) => s.selectedOptions[0].textContent)) !== path.basename(RIDGE)) {
      const before = await plans(page);
      await page.selectOption('#mission-select', { label: path.basename(RIDGE) });
      await waitReady(page, before);
    }
    await check(`${path.basename(RIDGE)} with --terrain: the profile under the map draws the route and the ground, its least clearance labelled as aloft mission --terrain gives it`, async () => {
      assert(cli.status === 1 && typeof cli.json.min_clearance_m === 'number', JSON.stringify(cli).slice(0, 300));
      const least = cli.json.min_clearance_m;
      const segment = cli.json.segments.find((s) => s.kind === 'leg' && s.min_clearance_m === least);
      const expected = `least clearance ${least.toFixed(1)} m, segment ${segment.index}`;
      // docs/terrain.md's figures for this mission.
      assert(expected === 'least clearance 2.6 m, segment 2', expected);
      const answer = await mapAnswer(server.url, RIDGE, readFileSync(RIDGE));
      const n = answer.profile.distance_m.length;
      await page.waitForSelector('#profile svg polyline.route-altitude', { timeout: 10000 });
      const drawn = await profileOf(page);
      assert(!drawn.hidden && drawn.height > 80 && drawn.mapHeight > 200, JSON.stringify(drawn));
      assert(drawn.label === expected && drawn.dot, JSON.stringify(drawn));
      assert(drawn.points === String(n) && drawn.route === n && drawn.ground === n + 2, `${n} points: ${JSON.stringify(drawn)}`);
      await page.locator('#profile').screenshot({ path: path.join(SHOTS, 'profile.png') });
    });
    await check("markup: a profile's values carrying markup are shown as text, nothing runs", async () => {
      await page.route('**/api/map?**', async (route) => {
        const response = await route.fetch();
        const map = await response.json().catch(() => ({}));
        if (map.profile && map.profile.least) map.profile.least.segment = evil('profile-segment');
        await route.fulfill({ response, json: map });
      });
      try {
        const before = await plans(page);
        await setOptions(page, { payload: '0.1' });
        await waitReady(page, before);
        const drawn = await profileOf(page);
        assert(drawn.label === `least clearance ${cli.json.min_clearance_m.toFixed(1)} m, segment –`, JSON.stringify(drawn));
        assert((await page.$$('#profile img')).length === 0, 'an image element was made');
        await assertClean(page, 'the profile');
      } finally {
        await page.unroute('**/api/map?**');
        const b2 = await plans(page);
        await setOptions(page, { payload: '' });
        await waitReady(page, b2);
      }
    });
    await check('the demo (placed in metres) is flown over a flat Earth: a plan, no profile', async () => {
      const before = await plans(page);
      await page.selectOption('#mission-select', 'demo');
      await waitReady(page, before);
      assert(await page.$eval('#error', (e) => e.hidden), 'an error shown');
      assert((await page.$$('#segments tbody tr')).length > 0, 'no plan');
      const drawn = await profileOf(page);
      assert(drawn.hidden && drawn.route === 0, JSON.stringify(drawn));
    });
    await page.context().close();
  } finally {
    server.stop();
  }
  const flat = await serve([RIDGE]);
  try {
    const page = await openPage(flat.url);
    await check(`${path.basename(RIDGE)} without --terrain: no profile`, async () => {
      const label = await page.$eval('#mission-select', (s) => s.selectedOptions[0].textContent);
      assert(label === path.basename(RIDGE), label);
      assert((await page.$$('#segments tbody tr')).length > 0, 'no plan');
      const drawn = await profileOf(page);
      assert(drawn.hidden && drawn.route === 0, JSON.stringify(drawn));
    });
    await page.context().close();
  } finally {
    flat.stop();
  }
}

async function noProblems() {
  await check(`no page error, console error nor dialog in any test (${expectedRefusals} expected 4xx answers logged by Chromium while refusals were tested)`, async () => {
    assert(pageProblems.length === 0 && dialogs.length === 0, pageProblems.concat(dialogs).join('\n'));
  });
}

// --- 9: the logbook's histories (`aloft serve --logbook FILE`): a logbook written by `aloft
// logbook add`, its lists served as the CLI's JSON; the panel opens on the vehicle the page flies
// (else the one with the latest flight); a vehicle's powers with a legend; the resistance of each
// pack of a vehicle its own line (the flugdrohne's logs filed under two packs).
async function logbookPanel() {
  const bookDir = mkdtempSync(path.join(os.tmpdir(), 'aloft-logbook-'));
  const book = path.join(bookDir, 'logbook.sqlite');
  const kaistDir = path.join(DATA, 'kaist_energy_drone');
  const ulgDir = path.join(DATA, 'px4_flugdrohne/ulg');
  const kaist = readdirSync(kaistDir).filter((f) => f.endsWith('.csv')).sort().map((f) => path.join(kaistDir, f));
  const ulgs = readdirSync(ulgDir).filter((f) => f.endsWith('.ulg')).sort().map((f) => path.join(ulgDir, f));
  const logbookCli = (args) => JSON.parse(execFileSync(BIN, ['logbook', ...args, '--db', book, '--format', 'json'], { encoding: 'utf8' }));
  logbookCli(['add', ...kaist, '--vehicle-label', 'kaist-m600']);
  logbookCli(['add', ...ulgs.slice(0, 2), '--pack-label', 'flugdrohne-3s-a']);
  logbookCli(['add', ...ulgs.slice(2), '--pack-label', 'flugdrohne-3s-b']);
  // The page flies a vehicle file named as the logbook's kaist-m600 (the M600's, renamed).
  const m600 = path.join(bookDir, 'kaist-m600.toml');
  writeFileSync(m600, readFileSync(path.join(repo, 'fixtures/vehicles/dji-m600.toml'), 'utf8').replace('name = "dji-m600"', 'name = "kaist-m600"'));
  const vehicles = logbookCli(['vehicles']).vehicles;
  const packs = logbookCli(['packs']).packs;
  const lb = await serve(['--logbook', book, '--vehicle', m600]);
  try {
    const page = await openPage(lb.url);
    for (const kind of ['flights', 'vehicles', 'packs']) {
      await check(`GET /api/logbook/${kind} equals aloft logbook ${kind} --format json`, async () => {
        const served = await page.evaluate((k) => fetch(`/api/logbook/${k}`).then((r) => r.json()), kind);
        const cli = logbookCli([kind]);
        assert(JSON.stringify(served) === JSON.stringify(cli), `${JSON.stringify(served).slice(0, 300)} vs ${JSON.stringify(cli).slice(0, 300)}`);
      });
    }
    await check(`the logbook panel lists the ${vehicles.length} vehicles and ${packs.length} packs`, async () => {
      await page.waitForSelector('#logbook-panel:not([hidden])');
      const v = await page.$$eval('#logbook-vehicle option', (os) => os.map((o) => o.textContent));
      const p = await page.$$eval('#logbook-pack option', (os) => os.map((o) => o.textContent));
      assert(v.length === vehicles.length && p.length === packs.length, `${v} / ${p}`);
    });
    await check('the logbook panel opens on the vehicle the page flies (kaist-m600), not the first listed', async () => {
      const at = vehicles.findIndex((v) => v.key === 'kaist-m600');
      assert(at > 0, `kaist-m600 is vehicle ${at} of the logbook`);
      assert((await page.$eval('#vehicle', (s) => s.value)) === 'kaist-m600', 'the page does not fly kaist-m600');
      const shown = await page.$eval('#logbook-vehicle', (s) => s.value);
      assert(shown === String(at), `vehicle ${shown} shown`);
      const summary = await page.textContent('#logbook-vehicle-summary');
      assert(summary.startsWith('kaist-m600: '), summary);
    });
    for (const v of vehicles) {
      const hover = v.power.filter((x) => typeof x.hover_power_w === 'number').length;
      const mean = v.power.filter((x) => typeof x.mean_power_w === 'number').length;
      await check(`vehicle ${v.key}: ${mean} mean and ${hover} hover powers charted, with a legend`, async () => {
        await page.selectOption('#logbook-vehicle', String(vehicles.indexOf(v)));
        const got = await page.evaluate(() => [
          document.querySelectorAll('#logbook-vehicle-chart circle.mean-power').length,
          document.querySelectorAll('#logbook-vehicle-chart circle.hover-power').length,
          document.querySelector('#logbook-vehicle-summary').textContent,
          [...document.querySelectorAll('#logbook-vehicle-chart g.legend text')].map((t) => t.textContent).join(','),
        ]);
        assert(got[0] === mean && got[1] === hover, JSON.stringify(got));
        assert(got[2].startsWith(`${v.key}: ${v.flights} flights`), got[2]);
        if (mean + hover > 0) assert(got[3] === 'mean power,hover power', `legend: ${got[3]}`);
      });
    }
    const flugdrohne = vehicles.find((v) => v.packs.includes('flugdrohne-3s-a'));
    const own = packs.filter((p) => flugdrohne.packs.includes(p.key) && p.resistance.length > 0);
    await check(`vehicle ${flugdrohne.key}: the resistance of each of its ${own.length} packs its own line, never one line through both`, async () => {
      assert(own.length === 2, `${own.length} packs with a resistance`);
      await page.selectOption('#logbook-vehicle', String(vehicles.indexOf(flugdrohne)));
      const lines = await page.$$eval('#logbook-pack-chart polyline.resistance', (ps) => ps.map((p) => p.getAttribute('points').trim().split(/\s+/).filter(Boolean).length));
      assert(lines.length === own.length, `${lines.length} lines: ${lines}`);
      assert(lines.slice().sort().join(',') === own.map((p) => p.resistance.length).sort().join(','), `${lines} vs ${own.map((p) => p.resistance.length)}`);
      const legend = await page.$$eval('#logbook-pack-chart g.legend text', (ts) => ts.map((t) => t.textContent).sort().join(','));
      assert(legend === own.map((p) => p.key).sort().join(','), legend);
    });
    const pack = packs.find((p) => p.key === 'flugdrohne-3s-b');
    await check(`pack flugdrohne-3s-b: its ${pack.resistance.length} resistances charted in mOhm, drawn over the other pack`, async () => {
      await page.selectOption('#logbook-pack', String(packs.indexOf(pack)));
      const cys = await page.$$eval('#logbook-pack-chart circle.resistance.selected', (cs) => cs.map((c) => c.querySelector('title').textContent));
      assert(cys.length === pack.resistance.length, `${cys.length}`);
      const first = `flight 1, flugdrohne-3s-b: ${(pack.resistance[0].value * 1000).toFixed(1)}`;
      assert(cys[0] === first, `${cys[0]} vs ${first}`);
      const summary = await page.textContent('#logbook-pack-summary');
      assert(summary.includes(`over ${pack.resistance_trend.n} flights`), summary);
    });
    await page.context().close();
  } finally {
    lb.stop();
  }
  // A page flying a vehicle the logbook does not know: the vehicle with the latest flight.
  const latest = (v) => Math.max(-Infinity, ...v.power.map((p) => (typeof p.start_unix_s === 'number' ? p.start_unix_s : -Infinity)));
  const newest = vehicles.reduce((b, v) => (latest(v) > latest(b) ? v : b), vehicles[0]);
  const other = await serve(['--logbook', book]);
  try {
    const page = await openPage(other.url);
    await check(`flying dji-m100, which the logbook does not know: the panel opens on the vehicle of the latest flight (${newest.key})`, async () => {
      await page.waitForSelector('#logbook-panel:not([hidden])');
      const shown = await page.$eval('#logbook-vehicle', (s) => s.value);
      assert(shown === String(vehicles.indexOf(newest)), `vehicle ${shown} shown`);
    });
    await page.context().close();
  } finally {
    other.stop();
    rmSync(bookDir, { recursive: true, force: true });
  }
}

// ------------------------------------------------------------------ markup in names (issue 41)

// Markup that runs script when it is parsed as HTML (an image that fails to load): `tag` says
// where it came from, in `window.__pwned` if it ever runs.
const evil = (tag) => `<img src=x onerror=window.__pwned='${tag}'>`;

// What ran in the page: `window.__pwned` and the policy's violations.
async function pwned(page) {
  return page.evaluate(() => ({ pwned: window.__pwned, violations: window.__violations || [] }));
}

async function assertClean(page, where) {
  await page.waitForTimeout(200); // an image's error event comes after its failed load
  const p = await pwned(page);
  assert(p.pwned === undefined, `${where}: markup ran (window.__pwned = ${p.pwned})`);
  assert(p.violations.length === 0, `${where}: policy violations: ${p.violations.join(' | ')}`);
  assert(dialogs.length === 0, `${where}: dialogs ${dialogs.join(' | ')}`);
}

// Move the mouse onto the middle of an SVG path of the map (a real hover: Leaflet opens its
// tooltip), and the tooltips' text then.
async function hoverPath(page, selector) {
  const at = await page.$eval(selector, (p) => {
    const q = p.getPointAtLength(p.getTotalLength() / 2);
    const m = p.getScreenCTM();
    return { x: q.x * m.a + q.y * m.c + m.e, y: q.x * m.b + q.y * m.d + m.f };
  });
  await page.mouse.move(at.x, at.y);
  await page.waitForTimeout(150);
  return page.$eval('#map', (m) => [...m.querySelectorAll('.leaflet-tooltip')].map((t) => t.textContent).join(' | '));
}

// Files whose names and contents carry markup, on every panel: the page shows each as text and
// no script runs (issue 41: a mission file's name ran in a sortie's tooltip).
async function markupEverywhere() {
  const dir = mkdtempSync(path.join(os.tmpdir(), 'aloft-markup-'));
  const demo = readFileSync(DEMO, 'utf8');
  const missionName = evil('mission-name');
  const givenMission = path.join(dir, `${evil('given-mission')}.toml`);
  writeFileSync(givenMission, demo.replace('name = "demo-survey"', `name = "${missionName}"`).replace(/^description = .*$/m, `description = "${evil('description')}"`));
  const givenLog = path.join(dir, `${evil('given-log')}.ulg`);
  writeFileSync(givenLog, readFileSync(path.join(DATA, 'flight_logs/pyulog_sample_log_small.ulg')));
  // A logbook whose vehicle, pack and file carry markup.
  const book = path.join(dir, 'logbook.sqlite');
  const ulg = readdirSync(path.join(DATA, 'px4_flugdrohne/ulg')).filter((f) => f.endsWith('.ulg')).sort()[0];
  const bookLog = path.join(dir, `${evil('logbook-file')}.ulg`);
  writeFileSync(bookLog, readFileSync(path.join(DATA, 'px4_flugdrohne/ulg', ulg)));
  execFileSync(BIN, ['logbook', 'add', bookLog, '--vehicle-label', evil('logbook-vehicle'), '--pack-label', evil('logbook-pack'), '--db', book], { stdio: 'ignore' });
  const server = await serve([givenMission, givenLog, '--logbook', book, '--tiles', '/vendor/leaflet/images/layers.png?{z}/{x}/{y}', '--attribution', evil('attribution')]);
  try {
    const page = await openPage(server.url);
    await check('markup: a given mission whose file name and name carry markup is listed and summarised as text', async () => {
      const label = await page.$eval('#mission-select', (s) => s.selectedOptions[0].textContent);
      assert(label === path.basename(givenMission), label);
      const summary = await page.$eval('#summary', (e) => e.textContent);
      assert(summary.includes(missionName), summary);
      assert((await page.$$('#summary img, #mission-select img')).length === 0, 'an image element was made');
      for (const k of [1, 3]) await hoverPath(page, `#map path.seg >> nth=${k}`);
      await hoverPath(page, '#map path.home');
      await assertClean(page, 'the given mission');
    });
    await check('markup: a given log whose file name carries markup is shown as text', async () => {
      await page.waitForSelector('#log .log-card', { timeout: 10000 });
      const text = await page.$eval('#log .log-card', (c) => c.textContent);
      assert(text.includes(path.basename(givenLog)), text);
      await assertClean(page, 'the given log');
    });
    await check('markup: the logbook panel shows vehicle and pack keys with markup as text', async () => {
      await page.waitForSelector('#logbook-panel:not([hidden])', { timeout: 10000 });
      const v = await page.$$eval('#logbook-vehicle option', (os) => os.map((o) => o.textContent).join(' | '));
      const p = await page.$$eval('#logbook-pack option', (os) => os.map((o) => o.textContent).join(' | '));
      // (The log names its vehicle: the label is the pack's only.)
      assert(p.includes(evil('logbook-pack')), `${v} / ${p}`);
      const summaries = await page.$eval('#logbook-panel', (e) => e.textContent);
      assert(summaries.includes(evil('logbook-pack')), summaries);
      assert((await page.$$('#logbook-panel img')).length === 0, 'an image element was made');
      await assertClean(page, 'the logbook');
    });
    const dropped = `${evil('dropped-plan')}.plan`;
    await check('markup: a dropped .plan named with markup is drawn on the tiles, its attribution (markup too) as text', async () => {
      const before = await plans(page);
      await dropFiles(page, [{ name: dropped, bytes: readFileSync(PLAN_MISSION) }]);
      await waitReady(page, before);
      const label = await page.$eval('#mission-select', (s) => s.selectedOptions[0].textContent);
      assert(label === `${dropped} (opened)`, label);
      await page.waitForSelector('#map .leaflet-control-attribution', { timeout: 10000 });
      const attribution = await page.$eval('#map .leaflet-control-attribution', (e) => e.textContent);
      assert(attribution.includes(evil('attribution')), attribution);
      await hoverPath(page, '#map path.seg >> nth=2');
      await assertClean(page, 'the dropped plan');
    });
    await check('markup: plan to fly names each sortie as the server does, as text, in the table and in the tooltips', async () => {
      const before = await plans(page);
      await setOptions(page, { reserve: '70', 'wind-speed': '8', 'wind-from': '0' });
      await waitReady(page, before);
      const [answer] = await Promise.all([
        page.waitForResponse((r) => r.url().includes('/api/plan?'), { timeout: 60000 }).then((r) => r.json()),
        page.click('#plan-fly'),
      ]);
      await page.waitForSelector('#fly[data-state="ready"] table.fly-sorties tbody tr', { timeout: 60000 });
      const names = answer.sorties.map((s) => s.file);
      assert(names.length >= 2, `${names.length} sorties`);
      const cells = await page.$$eval('#fly table.fly-sorties td.file', (tds) => tds.map((td) => td.textContent));
      assert(cells.join('\n') === names.join('\n'), `${cells} vs ${names}`);
      for (let k = 1; k <= names.length; k++) {
        const tip = await hoverPath(page, `#map path.fly-route.fly-sortie-${k}`);
        assert(tip.includes(`sortie ${k} (${names[k - 1]})`), `sortie ${k}: ${tip}`);
      }
      if (await page.$('#map path.fly-pnr')) await hoverPath(page, '#map path.fly-pnr');
      assert((await page.$$('#map img:not(.leaflet-tile), #fly img')).length === 0, 'an image element was made');
      await assertClean(page, 'the plan to fly');
    });
    await check('markup: a dropped vehicle file whose file name and name carry markup is listed and flown as text', async () => {
      const name = evil('vehicle-name');
      const text = readFileSync(path.join(repo, 'fixtures/vehicles/dji-inspire1.toml'), 'utf8').replace('name = "dji-inspire1"', `name = "${name}"`);
      const before = await plans(page);
      await dropFiles(page, [{ name: `${evil('vehicle-file')}.toml`, bytes: Buffer.from(text) }]);
      await waitReady(page, before);
      const options = await page.$$eval('#vehicle option', (os) => os.map((o) => o.textContent));
      assert(options.includes(name), options.join(' | '));
      const summary = await page.$eval('#summary', (e) => e.textContent);
      assert(summary.includes(name), summary);
      await page.waitForFunction((n) => document.querySelector('#sweep-title').textContent.includes(n), name, { timeout: 20000 });
      await assertClean(page, 'the dropped vehicle');
    });
    await check('markup: a dropped log named with markup, and a file the server cannot read, are shown as text', async () => {
      const name = `${evil('dropped-log')}.ulg`;
      await dropFiles(page, [{ name, bytes: readFileSync(path.join(DATA, 'flight_logs/pyulog_sample_log_small.ulg')) }]);
      await page.waitForFunction((n) => [...document.querySelectorAll('#log .log-card')].some((c) => c.textContent.includes(n)), name, { timeout: 20000 });
      const bad = `${evil('bad-file')}.bin`;
      await refusing(async () => {
        await dropFiles(page, [{ name: bad, bytes: Buffer.from('not a flight log at all\n') }]);
        await page.waitForFunction((n) => !document.querySelector('#error').hidden && document.querySelector('#error').textContent.includes(n), bad, { timeout: 20000 });
      });
      const badPlan = `${evil('bad-mission')}.toml`;
      await refusing(async () => {
        const before = await plans(page);
        await dropFiles(page, [{ name: badPlan, bytes: Buffer.from(`name = "${evil('bad-mission-name')}"\n[[segment]]\nkind = "nonsense"\n`) }]);
        await waitReady(page, before);
      });
      const shown = await page.$eval('#error', (e) => e.textContent);
      assert(shown.includes(badPlan), shown);
      assert((await page.$$('#log img, #error img')).length === 0, 'an image element was made');
      await assertClean(page, 'the dropped log and the refusals');
    });
    await check("markup: the plan's zip holds base names only, whatever names the server gives", async () => {
      // Back to the dropped plan (the last mission dropped was refused), flown by the M100.
      let before = await plans(page);
      await page.selectOption('#mission-select', { label: `${dropped} (opened)` });
      await waitReady(page, before);
      before = await plans(page);
      await page.selectOption('#vehicle', 'dji-m100');
      await waitReady(page, before);
      const hostile = ['../../escaped-1-of-3.plan', '..\\..\\escaped-2-of-3.plan', '/etc/cron.d/escaped-3-of-3.plan', '..'];
      await page.route('**/api/plan?**', async (route) => {
        const response = await route.fetch();
        const plan = await response.json().catch(() => ({}));
        const name = (_, k) => hostile[k % hostile.length];
        if (Array.isArray(plan.texts)) {
          plan.texts.forEach((t, k) => (t.file = name(t, k)));
          plan.sorties.forEach((s, k) => (s.file = name(s, k)));
          (plan.maps || []).forEach((m, k) => (m.file = name(m, k)));
          plan.files = plan.files.map(name);
        }
        await route.fulfill({ response, json: plan });
      });
      await page.click('#plan-fly');
      await page.waitForSelector('#fly[data-state="ready"] a.fly-all', { timeout: 60000 });
      const links = await page.$$eval('#fly a.fly-file', (as) => as.map((a) => a.getAttribute('download')));
      for (const l of links) assert(l && !/[\/\\]/.test(l) && !l.includes('..') && !l.startsWith('.'), `link ${l}`);
      const [zip] = await Promise.all([page.waitForEvent('download'), page.click('#fly a.fly-all')]);
      const zipPath = path.join(dir, 'plan.zip');
      await zip.saveAs(zipPath);
      const listed = JSON.parse(execFileSync('python3', ['-c', 'import json,sys,zipfile; z=zipfile.ZipFile(sys.argv[1]); print(json.dumps({"bad": z.testzip(), "names": z.namelist()}))', zipPath], { encoding: 'utf8' }));
      assert(listed.bad === null && listed.names.length === links.length, JSON.stringify(listed));
      for (const n of listed.names) assert(n && !/[\/\\]/.test(n) && !n.includes('..') && !n.startsWith('.'), `zip entry ${n}`);
      assert(new Set(listed.names).size === listed.names.length, `names repeat: ${listed.names}`);
      await page.unroute('**/api/plan?**');
      await assertClean(page, 'the zip');
    });
    await page.context().close();
  } finally {
    server.stop();
  }
  // The live panel: a followed telemetry log named with markup, at 4 times its speed (its first
  // 18 s carry a note: where the state of charge comes from).
  const tlog = path.join(dir, `${evil('tlog')}.tlog`);
  writeFileSync(tlog, readFileSync(TLOG));
  const lines = execFileSync(BIN, ['live', '--tlog', tlog, '--speed', 'max', '--format', 'json'], { encoding: 'utf8', maxBuffer: 1 << 26 }).trim().split('\n');
  const note = lines.map((l) => JSON.parse(l)).find((u) => typeof u.note === 'string').note;
  const live = await serve(['--tlog', tlog, '--speed', '4']);
  try {
    const page = await openPage(live.url);
    await check("markup: a followed telemetry log named with markup: the live panel shows its updates and aloft live's note as text, nothing runs", async () => {
      await page.waitForFunction(() => document.querySelector('#live') && document.querySelector('#live').dataset.mode, null, { timeout: 20000 });
      await page.waitForFunction((n) => [...document.querySelectorAll('#live dd')].some((d) => d.textContent === n), note, { timeout: 20000 });
      await page.waitForSelector('#map path.vehicle', { timeout: 10000 });
      await hoverPath(page, '#map path.vehicle');
      await assertClean(page, 'the live panel');
    });
    await page.context().close();
  } finally {
    live.stop();
    rmSync(dir, { recursive: true, force: true });
  }
}

try {
  await main();
} catch (e) {
  notOk('the run', e && e.stack ? e.stack : e);
} finally {
  if (browser) await browser.close().catch(() => {});
  killAll();
}
const seconds = ((Date.now() - started) / 1000).toFixed(1);
console.log(`# ${passed} passed, ${failed} failed in ${seconds} s`);
process.exit(failed === 0 && passed > 0 ? 0 : 1);
