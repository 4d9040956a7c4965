// Script both pages of CesiumJS runs share (tests/js/cesium-tiles.mjs, bench/cesium_first_frame.mjs),
// spliced into their HTML: a bare viewer (no imagery, terrain, globe or widgets) and the view a
// served /camera.json records (null when none is), so that runs on one model written two ways
// look from the same place.
import http from 'node:http';
import { readFile } from 'node:fs/promises';
import path from 'node:path';

export const cesiumPageHelpers = `
// onDemand: draw only when something changed (a tile loaded, the camera moved), not every
// animation frame; a test's software WebGL then spends no CPU on frames that show nothing new.
function bareViewer({ onDemand = false } = {}) {
  const viewer = new Cesium.Viewer('view', {
    baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false,
    animation: false, homeButton: false, sceneModePicker: false, navigationHelpButton: false,
    fullscreenButton: false, infoBox: false, selectionIndicator: false,
    globe: false, skyBox: false, skyAtmosphere: false,
    requestRenderMode: onDemand, maximumRenderTimeChange: Infinity,
  });
  return viewer;
}
async function servedView(viewer) {
  const camera = await (await fetch('/camera.json')).json();
  if (camera)
    viewer.camera.setView({ destination: Cesium.Cartesian3.fromArray(camera.position),
                            orientation: { direction: Cesium.Cartesian3.fromArray(camera.direction),
                                           up: Cesium.Cartesian3.fromArray(camera.up) } });
  return camera;
}
function cameraOf(viewer) {
  const c = viewer.camera;
  return { position: Cesium.Cartesian3.pack(c.position, []), direction: Cesium.Cartesian3.pack(c.direction, []),
           up: Cesium.Cartesian3.pack(c.up, []) };
}
`;


const types = { '.json': 'application/json', '.glb': 'model/gltf-binary', '.js': 'text/javascript',
                '.css': 'text/css', '.png': 'image/png', '.wasm': 'application/wasm',
                '.html': 'text/html', '.xml': 'application/xml', '.jpg': 'image/jpeg' };

// A loopback server for such a page: `page` at /, CesiumJS's build at /cesium/, the directory
// `tilesetDir()` names at /tileset/, `camera()` as /camera.json. `onServed(url, body)` sees each
// tileset file served, `onMissing(url)` each request it could not answer (404). Resolves to
// { server, port }.
export async function serveCesiumPage({ page, cesiumDir, tilesetDir, camera, onServed = () => {},
                                        onMissing = () => {} }) {
  const server = http.createServer(async (request, response) => {
    const url = decodeURIComponent(new URL(request.url, 'http://localhost').pathname);
    try {
      if (url === '/' || url === '/camera.json') {
        const json = url === '/camera.json';
        response.writeHead(200, { 'content-type': json ? 'application/json' : 'text/html' });
        response.end(json ? JSON.stringify(await camera()) : page);
        return;
      }
      let file = null;
      if (url.startsWith('/cesium/')) file = path.join(cesiumDir, url.slice('/cesium/'.length));
      else if (url.startsWith('/tileset/')) file = path.join(tilesetDir(), url.slice('/tileset/'.length));
      if (!file || file.includes('..')) throw new Error('outside');
      const body = await readFile(file);
      if (url.startsWith('/tileset/')) onServed(url, body);
      response.writeHead(200, { 'content-type': types[path.extname(file)] ?? 'application/octet-stream' });
      response.end(body);
    } catch {
      onMissing(url);
      response.writeHead(404);
      response.end();
    }
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { server, port: server.address().port };
}
