// The browser viewers end to end: `lodforge serve TILESET` on a free loopback port, each page
// (/cesium/, /three/) in Debian's headless chromium (playwright-core) until all tiles are
// loaded; fails on a console error, a failed or outside request, a tile failure, or a
// screenshot in which the model covers too little. A point tileset with LAS fields is drawn in
// every colour mode the panel offers (each must cover the view and differ from the one before),
// and hiding every class in the legend must empty the view.
// With --texture-hues, the tileset's texture is red and blue: both colours must show.
//   node web-viewers.mjs LODFORGE TILESET_DIR OUT_DIR [--min-coverage 0.02] [--texture-hues F]
//                        [--same-drawn]
import { spawn } from 'node:child_process';
import { existsSync, readFileSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { coverageOf, differenceOf, hueSharesOf, keepLocal, launchChromium } from './chromium.mjs';

const [lodforge, tilesetDir, outDir] = process.argv.slice(2);
const coverageArg = process.argv.indexOf('--min-coverage');
const minCoverage = coverageArg > 0 ? Number(process.argv[coverageArg + 1]) : 0.02;
// A tileset of a red and blue texture: each colour must cover at least this share of the
// model's pixels.
const huesArg = process.argv.indexOf('--texture-hues');
const minHue = huesArg > 0 ? Number(process.argv[huesArg + 1]) : 0;
// With --same-drawn, both viewers must draw the same triangles (tiles whose errors both read
// from the same place: an implicit tileset's metadata).
const sameDrawn = process.argv.includes('--same-drawn');
const drawnTriangles = {};
if (!lodforge || !tilesetDir || !outDir) {
  console.error('usage: node web-viewers.mjs LODFORGE TILESET_DIR OUT_DIR [--min-coverage F]');
  process.exit(2);
}

// The server picks a free port and says which.
const server = spawn(lodforge, ['serve', tilesetDir, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
let serverLog = '';
server.stderr.on('data', (d) => { serverLog += d; });
const port = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/http:\/\/127\.0\.0\.1:(\d+)\//);
    if (m) resolve(Number(m[1]));
  });
  server.on('exit', (code) => reject(new Error(`lodforge serve exited with ${code}: ${serverLog}`)));
  // unref: a pending timer would keep node alive for its full 20 s after the test is done.
  setTimeout(() => reject(new Error('lodforge serve did not start')), 20000).unref();
});

// Runs fn(arg) in the page, a change made through window.lodforge, and waits until the viewer
// has drawn a frame after it (its own frame counter), not a fixed time. Both pages draw only
// when something changed, so this also checks that each change asks for a frame.
async function change(tab, fn, arg) {
  const from = await tab.evaluate(() => window.lodforge.frames);
  await tab.evaluate(fn, arg);
  await drawnSince(tab, from);
}

async function drawnSince(tab, from) {
  await tab.waitForFunction((n) => window.lodforge.frames > n, from, { timeout: 60000 });
}

// `count` of the browser's animation frames (two: a viewer draws what it has pending in the next).
async function browserFrames(tab, count = 2) {
  await tab.evaluate((n) => new Promise((done) => {
    const next = () => (--n > 0 ? requestAnimationFrame(next) : done());
    requestAnimationFrame(next);
  }), count);
}

// Each colour mode draws (covers the view) and draws differently from the mode before; hiding
// every class leaves (almost) nothing, showing them again brings the points back.
async function checkColorModes(tab, viewer, coverage, firstPng, mine) {
  const modes = await tab.evaluate(() => window.lodforge.colorModes);
  let previous = firstPng;
  const shots = [];
  for (const [i, mode] of modes.entries()) {
    await change(tab, (m) => window.lodforge.setColorMode(m), mode);
    const png = await tab.screenshot();
    writeFileSync(path.join(outDir, `${viewer}-${mode.replace(' ', '-')}.png`), png);
    const covered = await coverageOf(tab, png, [0x12, 0x15, 0x1a], 'panel');
    const changed = i === 0 ? 1 : await differenceOf(tab, previous, png, 'panel');
    shots.push(`${mode} ${(100 * covered).toFixed(1)} % covered, ${(100 * changed).toFixed(1)} % changed`);
    if (covered < minCoverage) mine(`colour mode ${mode}: the model covers ${(100 * covered).toFixed(2)} %`);
    if (i > 0 && changed < 0.005) mine(`colour mode ${mode} draws like ${modes[i - 1]} (${(100 * changed).toFixed(2)} % of pixels changed)`);
    previous = png;
  }
  const classes = await tab.evaluate(() => window.lodforge.classes());
  if (classes.length === 0) mine('the legend lists no class');
  await tab.evaluate(() => window.lodforge.setColorMode('classification'));
  await change(tab, (list) => { for (const c of list) window.lodforge.setClassVisible(c, false); }, classes);
  const hiddenPng = await tab.screenshot();
  writeFileSync(path.join(outDir, `${viewer}-classes-hidden.png`), hiddenPng);
  const hidden = await coverageOf(tab, hiddenPng, [0x12, 0x15, 0x1a], 'panel');
  await change(tab, (list) => { for (const c of list) window.lodforge.setClassVisible(c, true); }, classes);
  const shown = await coverageOf(tab, await tab.screenshot(), [0x12, 0x15, 0x1a], 'panel');
  console.log(`${viewer}: colour modes: ${shots.join('; ')}; classes ${classes.join(',')} hidden: ` +
              `${(100 * hidden).toFixed(2)} % covered, shown again: ${(100 * shown).toFixed(1)} %`);
  if (hidden > 0.1 * coverage) mine(`with every class hidden the model still covers ${(100 * hidden).toFixed(2)} %`);
  if (shown < minCoverage) mine(`with the classes shown again the model covers ${(100 * shown).toFixed(2)} %`);
}

// A tileset of parts: the viewer finds a known part by name (one the root tile still holds, the
// largest) and flies to it; with every other part hidden, the pixels that pick anything pick it,
// highlighted; a real click on one shows its name and path in the panel, as parts.json has them;
// hiding it leaves that pixel to another part or to nothing. Where the parts are on CAD layers,
// the pick and the panel name the part's layer, and turning its layer off hides it.
async function checkParts(tab, viewer, mine) {
  const parts = JSON.parse(readFileSync(path.join(tilesetDir, 'parts.json'), 'utf8'));
  const inRoot = new Set(parts.parts.map((p) => p.id));
  for (const id of parts.levels[parts.levels.length - 1].missing) inRoot.delete(id);
  const size = (p) => (p.bounds ? Math.hypot(p.bounds[3] - p.bounds[0], p.bounds[4] - p.bounds[1], p.bounds[5] - p.bounds[2]) : 0);
  const known = parts.parts.filter((p) => inRoot.has(p.id)).sort((a, b) => size(b) - size(a))[0];
  const count = await tab.evaluate(() => window.lodforge.parts.count);
  if (count !== parts.parts.length) mine(`the viewer has ${count} parts, parts.json ${parts.parts.length}`);
  const found = await tab.evaluate((name) => window.lodforge.parts.find(name), known.name);
  if (!found.includes(known.id)) mine(`finding "${known.name}" gave ${JSON.stringify(found)}`);
  await change(tab, (id) => window.lodforge.parts.isolate(id), known.id);
  await tab.waitForFunction(() => window.lodforge.parts.idle(), null, { timeout: 60000 });
  await browserFrames(tab);
  const box = await tab.evaluate(() => { const r = document.querySelector('canvas').getBoundingClientRect(); return [r.width, r.height]; });
  // The whole grid in one call: each call into the page waits for the frame being drawn (a
  // few hundred ms in software WebGL), the picks themselves take a few ms.
  const grid = [];
  for (let j = 1; j < 16; ++j)
    for (let i = 1; i < 24; ++i) grid.push([Math.round((box[0] * i) / 24), Math.round((box[1] * j) / 16)]);
  const hits = (await tab.evaluate((points) => points.map(([x, y]) => {
    const hit = window.lodforge.parts.pick(x, y);
    return hit ? { x, y, ...hit } : null;
  }), grid)).filter((h) => h);
  writeFileSync(path.join(outDir, `${viewer}-part.png`), await tab.screenshot());
  const others = hits.filter((h) => h.id !== known.id);
  console.log(`${viewer}: "${known.name}" (part ${known.id} of ${count}) found and isolated: ` +
              `${hits.length} of 345 pixels pick it, ${others.length} pick another part`);
  if (hits.length === 0) { mine(`part "${known.name}" is not on screen after finding it`); return; }
  if (others.length > 0) mine(`with "${known.name}" isolated, pixels pick ${JSON.stringify(others[0])}`);
  for (const h of hits) {
    if (h.name !== known.name) mine(`the tile names part ${h.id} "${h.name}", parts.json "${known.name}"`);
    if (!h.highlighted) mine(`part ${h.id} is not highlighted after finding it`);
  }
  // A pixel the panel does not cover, where a real click reaches the canvas.
  const panel = await tab.evaluate(() => { const r = document.getElementById('panel').getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; });
  const clear = hits.filter((h) => h.x < panel[0] || h.x > panel[2] || h.y < panel[1] || h.y > panel[3]);
  if (clear.length === 0) { mine(`every pixel of part "${known.name}" lies under the panel`); return; }
  const hit = clear[Math.floor(clear.length / 2)];
  const box0 = await tab.evaluate(() => { const r = document.querySelector('canvas').getBoundingClientRect(); return [r.left, r.top]; });
  const beforeClick = await tab.evaluate(() => window.lodforge.frames);
  await tab.mouse.click(box0[0] + hit.x, box0[1] + hit.y);
  await drawnSince(tab, beforeClick);
  const shown = await tab.evaluate(() => window.lodforge.parts.shown());
  if (!shown.includes(known.name) || !shown.includes(known.path))
    mine(`clicking part ${known.id} shows "${shown}", not its name "${known.name}" and path "${known.path}"`);
  if (parts.parts.some((p) => p.layer)) await checkLayers(tab, viewer, known, hit, shown, mine);
  await tab.evaluate(() => window.lodforge.parts.showAll());
  await change(tab, (id) => window.lodforge.parts.hide(id), known.id);
  const after = await tab.evaluate(([px, py]) => window.lodforge.parts.pick(px, py), [hit.x, hit.y]);
  if (after && after.id === known.id) mine(`part ${known.id} is still picked after hiding it`);
  console.log(`${viewer}: a click shows "${shown}"; hidden, its pixel picks ${after ? `"${after.name}"` : 'nothing'}`);
}

// The known part's CAD layer: in what its pixel picks (CesiumJS reads it from the tile's property
// table), in the panel after a click, and in the layer list; with its layer off, the pixel no
// longer picks it; back on, it does again.
async function checkLayers(tab, viewer, known, hit, shown, mine) {
  if (!known.layer) { mine(`part "${known.name}" has no layer in a tileset of layers`); return; }
  if (hit.layer !== known.layer) mine(`the tile gives part ${known.id} layer "${hit.layer}", parts.json "${known.layer}"`);
  if (!shown.includes(known.layer)) mine(`clicking part ${known.id} shows "${shown}", not its layer "${known.layer}"`);
  const layers = await tab.evaluate(() => window.lodforge.parts.layers());
  const name = known.layer.split('; ')[0];
  if (!layers.includes(name)) { mine(`the layer list ${JSON.stringify(layers)} lacks "${name}"`); return; }
  await tab.evaluate(() => window.lodforge.parts.showAll());
  await change(tab, ([id, layer]) => { window.lodforge.parts.isolate(id); window.lodforge.parts.setLayer(layer, false); },
               [known.id, name]);
  const off = await tab.evaluate(([px, py]) => window.lodforge.parts.pick(px, py), [hit.x, hit.y]);
  if (off && off.id === known.id) mine(`part ${known.id} is still picked with its layer "${name}" off`);
  await change(tab, (layer) => window.lodforge.parts.setLayer(layer, true), name);
  const on = await tab.evaluate(([px, py]) => window.lodforge.parts.pick(px, py), [hit.x, hit.y]);
  if (!on || on.id !== known.id) mine(`part ${known.id} is not picked again with its layer "${name}" back on`);
  console.log(`${viewer}: part ${known.id} is on layer "${known.layer}" (${layers.length} layers); ` +
              `off, its pixel picks ${off ? `"${off.name}"` : 'nothing'}; on again, "${on ? on.name : 'nothing'}"`);
}

const { context, close: closeBrowser } = await launchChromium();
const problems = [];
try {
  for (const viewer of ['cesium', 'three']) {
    const tab = await context.newPage();
    const mine = (p) => problems.push(`${viewer}: ${p}`);
    await keepLocal(tab, mine);
    tab.on('console', (m) => { if (m.type() === 'error') mine(`console: ${m.text()}`); });
    tab.on('pageerror', (e) => mine(`page error: ${e.message}`));
    tab.on('requestfailed', (r) => mine(`request failed: ${r.url()}`));
    tab.on('response', (r) => { if (r.status() >= 400) mine(`HTTP ${r.status()}: ${r.url()}`); });
    // Each tile is downloaded once while the three.js view first loads (the part ids come from
    // the parse, not from a second download). CesiumJS's own scheduler may ask again for a tile
    // it cancelled, so its page is not held to this.
    const tileGets = new Map();
    tab.on('request', (r) => {
      if (r.url().endsWith('.glb')) tileGets.set(r.url(), (tileGets.get(r.url()) ?? 0) + 1);
    });
    await tab.goto(`http://127.0.0.1:${port}/${viewer}/`);
    await tab.waitForFunction(() => window.lodforge && (window.lodforge.loaded || window.lodforge.error ||
                                                        window.lodforge.failed.length > 0),
                              null, { timeout: 240000 });
    const report = await tab.evaluate(() => window.lodforge);
    if (report.error) mine(`viewer: ${report.error}`);
    for (const f of report.failed) mine(`tile failed: ${f}`);
    if (report.tilesLoaded < 1) mine('no tile loaded');
    // Loaded means drawn (CesiumJS says so in the frame that draws the last tile); two more
    // animation frames give a viewer time to ask for a tile twice.
    await browserFrames(tab);
    // Loaded and left alone, a viewer draws on demand only: over ten of the browser's animation
    // frames it draws at most a trailing frame or two (CesiumJS may ask for one after the last
    // tile), where a viewer drawing all the time draws one in each.
    const idleFrom = await tab.evaluate(() => window.lodforge.frames);
    await browserFrames(tab, 10);
    const idleTo = await tab.evaluate(() => window.lodforge.frames);
    if (idleTo - idleFrom > 2) mine(`left alone after loading, the view drew ${idleTo - idleFrom} frames in 10`);
    const twice = [...tileGets].filter(([, n]) => n > 1);
    if (viewer === 'three' && twice.length > 0) mine(`${twice.length} tile(s) downloaded more than once, e.g. ${twice[0][0]}`);
    const stats = await tab.evaluate(() => document.getElementById('stats').textContent);
    drawnTriangles[viewer] = (stats.match(/([\d,]+) triangles/) ?? [, 'none'])[1];
    const png = await tab.screenshot();
    const shot = path.join(outDir, `${viewer}.png`);
    writeFileSync(shot, png);
    // Share of pixels that differ from the page's background (#12151a) and the panel.
    const coverage = await coverageOf(tab, png, [0x12, 0x15, 0x1a], 'panel');
    // Each viewer opens on the whole tileset: every corner of the root's box on screen.
    const view = await tab.evaluate(() => [window.innerWidth, window.innerHeight, window.lodforge.rootCorners()]);
    const off = view[2].filter((c) => !c || c[0] < 0 || c[1] < 0 || c[0] > view[0] || c[1] > view[1]);
    if (view[2].length === 0) mine('the viewer gives no corner of the root box');
    if (off.length > 0) mine(`${off.length} of the root box's ${view[2].length} corners are off screen: ${JSON.stringify(off[0])}`);
    console.log(`${viewer}: ${report.tilesLoaded} tiles loaded, "${stats}", model covers ${(100 * coverage).toFixed(1)} % (${shot})`);
    if (coverage < minCoverage) mine(`the model covers ${(100 * coverage).toFixed(2)} % of the view`);
    if (minHue > 0) {
      const hues = await hueSharesOf(tab, png, 'panel');
      const red = hues.red / coverage, blue = hues.blue / coverage;
      console.log(`${viewer}: the texture's red is ${(100 * red).toFixed(1)} % of the model's pixels, its blue ${(100 * blue).toFixed(1)} %`);
      if (red < minHue || blue < minHue)
        mine(`the texture is not drawn: red ${(100 * red).toFixed(2)} %, blue ${(100 * blue).toFixed(2)} % of the model's pixels`);
    }
    if (report.colorModes) await checkColorModes(tab, viewer, coverage, png, mine);
    if (existsSync(path.join(tilesetDir, 'parts.json'))) {
      if (!report.parts) mine('the tileset has parts.json, the viewer offers no parts');
      else await checkParts(tab, viewer, mine);
    }
    await tab.close();
  }
  if (sameDrawn && drawnTriangles.cesium !== drawnTriangles.three)
    problems.push(`CesiumJS draws ${drawnTriangles.cesium} triangles, three.js ${drawnTriangles.three}`);
} catch (e) {
  problems.push(String(e));
} finally {
  await closeBrowser();
  server.kill('SIGINT');
}
const exitCode = await new Promise((resolve) => server.on('exit', (code) => resolve(code)));
if (exitCode !== 0) problems.push(`lodforge serve exited with ${exitCode} after Ctrl-C`);
if (problems.length > 0) {
  for (const p of problems) console.error(p);
  process.exit(1);
}
console.log('both viewers loaded every tile without errors; serve stopped cleanly');
