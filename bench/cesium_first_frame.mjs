// Time to the first frame in CesiumJS, explicit against implicit tiling (issue 38): each tileset
// directory is opened in Debian's headless chromium from a local HTTP server, several times,
// interleaved, all from the camera a first untimed run set on the first directory's model (its
// root's sphere, or an implicit root's first child's: the tight box of its metadata); per run
// the time until Cesium3DTileset.fromUrl resolves (tileset.json fetched and parsed, the tile
// tree made), until the first tile content is loaded, and until every tile of the view is
// (the first allTilesLoaded), with the bytes of tileset.json, subtree files and contents fetched
// by then. Prints a markdown table of the medians.
//   node bench/cesium_first_frame.mjs [--runs 3] TILESET_DIR...
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { cesiumPageHelpers, serveCesiumPage } from '../tests/js/cesium-page.mjs';
import { keepLocal, launchChromium } from '../tests/js/chromium.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const cesiumDir = path.join(here, '../tests/js/node_modules/cesium/Build/Cesium');
const args = process.argv.slice(2);
const runsArg = args.indexOf('--runs');
const runs = runsArg >= 0 ? Number(args.splice(runsArg, 2)[1]) : 3;
const directories = args;
if (directories.length === 0) {
  console.error('usage: node bench/cesium_first_frame.mjs [--runs N] TILESET_DIR...');
  process.exit(2);
}

const page = `<!doctype html>
<html><head><meta charset="utf-8">
<script>window.CESIUM_BASE_URL = '/cesium/';</script>
<script src="/cesium/Cesium.js"></script>
<style>html, body, #view { margin: 0; width: 100%; height: 100%; overflow: hidden; }</style>
</head><body><div id="view"></div><script>
${cesiumPageHelpers}
window.report = { error: null };
(async () => {
  try {
    const viewer = bareViewer();
    // Every run looks from the camera of a first, untimed one on the first tileset's model (an
    // implicit root's volume is the whole octree cube: zooming to it frames differently).
    const camera = await servedView(viewer);
    const start = performance.now();
    const tileset = await Cesium.Cesium3DTileset.fromUrl('/tileset/tileset.json');
    window.report.parsed = performance.now() - start;
    tileset.tileLoad.addEventListener((tile) => {
      if (tile.hasImplicitContent) return;  // a subtree file, not a model
      if (window.report.firstContent === undefined) window.report.firstContent = performance.now() - start;
    });
    tileset.allTilesLoaded.addEventListener(() => {
      if (window.report.done) return;
      window.report.done = true;
      const initial = performance.now() - start;
      window.fetchedBytes().then((bytes) => {
        window.report.initialBytes = bytes;
        window.report.initial = initial;
      });
    });
    viewer.scene.primitives.add(tileset);
    if (!camera) {
      // The model's own sphere: the root's, or an implicit root's first child's (its metadata box).
      let sphere = tileset.boundingSphere;
      viewer.camera.viewBoundingSphere(sphere, new Cesium.HeadingPitchRange(0, -0.5, 0));
      if (tileset.root.implicitTileset) {  // in view, its first subtree loads
        while (tileset.root.children.length === 0) await new Promise((r) => setTimeout(r, 50));
        sphere = tileset.root.children[0].boundingSphere;
      }
      viewer.camera.viewBoundingSphere(sphere, new Cesium.HeadingPitchRange(0, -0.5, 0));
      viewer.camera.lookAtTransform(Cesium.Matrix4.IDENTITY);
      window.report.camera = cameraOf(viewer);
    }
  } catch (e) {
    window.report.error = String(e && e.stack || e);
  }
})();
</script></body></html>`;

// Bytes served per kind, reset per run.
let served = { json: 0, subtree: 0, glb: 0 };
let tilesetDir = null;
let camera = null;  // the view of every timed run
const { server, port } = await serveCesiumPage({
  page, cesiumDir, tilesetDir: () => tilesetDir, camera: async () => camera,
  onServed: (url, body) => {
    served[url.endsWith('.json') ? 'json' : url.endsWith('.subtree') ? 'subtree' : 'glb'] += body.length;
  },
});

async function measure(directory) {
  tilesetDir = directory;
  served = { json: 0, subtree: 0, glb: 0 };
  const { context, close } = await launchChromium();
  try {
    const tab = context.pages()[0] ?? await context.newPage();
    await keepLocal(tab, (p) => { throw new Error(p); });
    await tab.exposeFunction('fetchedBytes', () => ({ ...served }));
    await tab.goto(`http://127.0.0.1:${port}/`);
    await tab.waitForFunction((needCamera) => window.report.error ||
                                  (window.report.initial !== undefined && (!needCamera || window.report.camera)),
                              camera === null, { timeout: Number(process.env.FIRST_FRAME_TIMEOUT_MS ?? 600000) });
    const report = await tab.evaluate(() => window.report);
    if (report.error) throw new Error(report.error);
    return report;
  } finally {
    await close();
  }
}

const median = (values) => [...values].sort((a, b) => a - b)[Math.floor(values.length / 2)];
camera = (await measure(directories[0])).camera;
const results = new Map(directories.map((d) => [d, []]));
for (let r = 0; r < runs; r++)
  for (const d of directories) results.get(d).push(await measure(d));
server.close();

const mb = (bytes) => (bytes / 1e6).toFixed(2);
console.log('| tileset | tileset.json | parsed (ms) | first content (ms) | view loaded (ms) | fetched by then: json / subtrees / contents (MB) |');
console.log('|---|---:|---:|---:|---:|---|');
for (const [d, reports] of results) {
  const json = (await readFile(path.join(d, 'tileset.json'))).length;
  const bytes = reports[0].initialBytes;
  console.log(`| ${path.basename(d)} | ${mb(json)} MB | ${median(reports.map((x) => x.parsed)).toFixed(0)} | ` +
              `${median(reports.map((x) => x.firstContent)).toFixed(0)} | ${median(reports.map((x) => x.initial)).toFixed(0)} | ` +
              `${mb(bytes.json)} / ${mb(bytes.subtree)} / ${mb(bytes.glb)} |`);
}
