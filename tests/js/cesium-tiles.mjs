// Loads a tileset lodforge wrote in CesiumJS, in Debian's headless chromium (playwright-core),
// from a local HTTP server: waits until every tile is loaded, fails on any tile failure, failed
// request or console error, and checks that the screenshot shows the model.
//   node cesium-tiles.mjs TILESET_DIR SCREENSHOT.png [--min-coverage 0.02]
import http from 'node:http';
import { readFile, writeFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { coverageOf, keepLocal, launchChromium } from './chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const [tilesetDir, screenshot] = process.argv.slice(2);
const coverageArg = process.argv.indexOf('--min-coverage');
const minCoverage = coverageArg > 0 ? Number(process.argv[coverageArg + 1]) : 0.02;
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
window.report = { failed: [], loaded: false, error: null };
(async () => {
  try {
    const viewer = new Cesium.Viewer('view', {
      baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false,
      animation: false, homeButton: false, sceneModePicker: false, navigationHelpButton: false,
      fullscreenButton: false, infoBox: false, selectionIndicator: false,
      terrainProvider: new Cesium.EllipsoidTerrainProvider(), skyBox: false, skyAtmosphere: false,
    });
    viewer.scene.globe.show = false;
    viewer.scene.backgroundColor = Cesium.Color.BLACK;
    const tileset = await Cesium.Cesium3DTileset.fromUrl('/tileset/tileset.json',
                                                         { maximumScreenSpaceError: 4 });
    tileset.tileFailed.addEventListener((e) => window.report.failed.push(e.url + ': ' + e.message));
    viewer.scene.primitives.add(tileset);
    await viewer.zoomTo(tileset);
    tileset.allTilesLoaded.addEventListener(() => { window.report.loaded = true; });
  } catch (e) {
    window.report.error = String(e && e.stack || e);
  }
})();
</script></body></html>`;

const types = { '.json': 'application/json', '.glb': 'model/gltf-binary', '.js': 'text/javascript',
                '.css': 'text/css', '.png': 'image/png', '.wasm': 'application/wasm',
                '.html': 'text/html', '.xml': 'application/xml', '.jpg': 'image/jpeg' };
const failedRequests = [];
const server = http.createServer(async (request, response) => {
  const url = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
  let file = null;
  if (url === '/') file = null;
  else if (url.startsWith('/cesium/')) file = path.join(cesiumDir, url.slice('/cesium/'.length));
  else if (url.startsWith('/tileset/')) file = path.join(tilesetDir, url.slice('/tileset/'.length));
  try {
    if (url === '/') {
      response.writeHead(200, { 'content-type': 'text/html' });
      response.end(page);
      return;
    }
    if (!file || file.includes('..')) throw new Error('outside');
    const body = await readFile(file);
    response.writeHead(200, { 'content-type': types[path.extname(file)] ?? 'application/octet-stream' });
    response.end(body);
  } catch {
    failedRequests.push(url);
    response.writeHead(404);
    response.end();
  }
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const port = server.address().port;

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
