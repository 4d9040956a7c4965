// Loads a tileset lodforge wrote in CesiumJS, in Debian's headless chromium (playwright-core),
// from a local HTTP server: waits until every tile is loaded, fails on any tile failure, failed
// request or console error, and checks that the screenshot shows the model. Writes beside the
// screenshot SCREENSHOT.json: the contents fetched and their bytes. With --same-as OTHER.png
// (a run on the same model written another way: implicit tiling), seen from that run's camera,
// the picture must match that one's and the same contents must have been fetched.
//   node cesium-tiles.mjs TILESET_DIR SCREENSHOT.png [--min-coverage 0.02] [--same-as OTHER.png]
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { cesiumPageHelpers, serveCesiumPage } from './cesium-page.mjs';
import { coverageOf, differenceOf, keepLocal, launchChromium } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const [tilesetDir, screenshot] = process.argv.slice(2);
const coverageArg = process.argv.indexOf('--min-coverage');
const minCoverage = coverageArg > 0 ? Number(process.argv[coverageArg + 1]) : 0.02;
const sameArg = process.argv.indexOf('--same-as');
const sameAs = sameArg > 0 ? process.argv[sameArg + 1] : null;
if (!tilesetDir || !screenshot) {
  console.error('usage: node cesium-tiles.mjs TILESET_DIR SCREENSHOT.png [--min-coverage F]');
  process.exit(2);
}
const cesiumDir = path.join(here, 'node_modules/cesium/Build/Cesium');

const page = `<!doctype html>
<html><head><meta charset="utf-8">
<script>window.CESIUM_BASE_URL = '/cesium/';</script>
<script src="/cesium/Cesium.js"></script>
<link rel="stylesheet" href="/cesium/Widgets/widgets.css">
<style>html, body, #view { margin: 0; width: 100%; height: 100%; overflow: hidden; }</style>
</head><body><div id="view"></div><script>
${cesiumPageHelpers}
window.report = { failed: [], loaded: false, error: null };
(async () => {
  try {
    const viewer = bareViewer({ onDemand: true });
    viewer.scene.backgroundColor = Cesium.Color.BLACK;
    const tileset = await Cesium.Cesium3DTileset.fromUrl('/tileset/tileset.json',
                                                         { maximumScreenSpaceError: 4 });
    tileset.tileFailed.addEventListener((e) => window.report.failed.push(e.url + ': ' + e.message));
    viewer.scene.primitives.add(tileset);
    // The other run's camera (--same-as): an implicit tileset's root volume is the whole octree
    // cube, so zooming to it would frame the model differently.
    if (!(await servedView(viewer))) await viewer.zoomTo(tileset);
    window.report.camera = cameraOf(viewer);
    tileset.allTilesLoaded.addEventListener(() => { window.report.loaded = true; });
  } catch (e) {
    window.report.error = String(e && e.stack || e);
  }
})();
</script></body></html>`;

const failedRequests = [];
const fetched = { contents: [], bytes: 0 };
const { server, port } = await serveCesiumPage({
  page, cesiumDir, tilesetDir: () => tilesetDir,
  // The other run's camera (--same-as), or none.
  camera: async () => (sameAs ? JSON.parse(await readFile(sameAs.replace(/\.png$/, '.json'), 'utf8')).camera : null),
  onServed: (url, body) => {
    if (!url.endsWith('.glb')) return;
    fetched.contents.push(url);
    fetched.bytes += body.length;
  },
  onMissing: (url) => failedRequests.push(url),
});

const { context, close: closeBrowser } = await launchChromium();
const problems = [];
try {
  const tab = context.pages()[0] ?? await context.newPage();
  await keepLocal(tab, (p) => problems.push(p));
  tab.on('console', (m) => { if (m.type() === 'error') problems.push(`console: ${m.text()}`); });
  tab.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  tab.on('requestfailed', (r) => problems.push(`request failed: ${r.url()}`));
  await tab.goto(`http://127.0.0.1:${port}/`);
  await tab.waitForFunction(() => window.report.loaded || window.report.error ||
                                   window.report.failed.length > 0, null, { timeout: 180000 });
  const report = await tab.evaluate(() => window.report);
  if (report.error) problems.push(`viewer: ${report.error}`);
  for (const f of report.failed) problems.push(`tile failed: ${f}`);
  await tab.waitForTimeout(500);
  const png = await tab.screenshot();
  await writeFile(screenshot, png);
  // Share of pixels that are not the black background.
  const coverage = await coverageOf(tab, png, [0, 0, 0]);
  console.log(`coverage ${(100 * coverage).toFixed(1)} % of the pixels; screenshot ${screenshot}`);
  if (coverage < minCoverage) problems.push(`the model covers ${(100 * coverage).toFixed(2)} % of the view`);
  await writeFile(screenshot.replace(/\.png$/, '.json'),
                  JSON.stringify({ contents: fetched.contents.length, bytes: fetched.bytes,
                                   camera: report.camera }));
  console.log(`fetched ${fetched.contents.length} contents, ${fetched.bytes} bytes`);
  if (sameAs) {
    const other = JSON.parse(await readFile(sameAs.replace(/\.png$/, '.json'), 'utf8'));
    const difference = await differenceOf(tab, png, await readFile(sameAs));
    console.log(`${(100 * difference).toFixed(2)} % of the pixels differ from ${sameAs}`);
    if (difference > 0.005) problems.push(`the picture differs from ${sameAs} in ${(100 * difference).toFixed(2)} % of its pixels`);
    if (other.contents !== fetched.contents.length || other.bytes !== fetched.bytes)
      problems.push(`fetched ${fetched.contents.length} contents (${fetched.bytes} bytes), ${sameAs} ${other.contents} (${other.bytes} bytes)`);
  }
} catch (e) {
  problems.push(String(e));
} finally {
  await closeBrowser();
  server.close();
}
for (const url of failedRequests) problems.push(`not served: ${url}`);
if (problems.length > 0) {
  for (const p of problems) console.error(p);
  process.exit(1);
}
console.log('CesiumJS loaded every tile without errors');
