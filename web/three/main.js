// three.js viewer with NASA-AMMOS 3d-tiles-renderer for the tileset at /tiles/: the tileset is
// moved to the origin (a georeferenced one sits 6,000 km away in ECEF) and turned so its local
// up is +y, an orbit camera frames it; stats and a screen-space-error slider as on the Cesium
// page. window.lodforge reports to tests.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { MeshoptDecoder } from 'three/examples/jsm/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer';
import { GLTFExtensionsPlugin } from '3d-tiles-renderer/plugins';
import { drawnSummary, formatBytes, formatCount, onScreenSpaceError } from '../format.js';

const report = (window.lodforge = { loaded: false, failed: [], error: null, tilesLoaded: 0 });

function main() {
  const renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.setClearColor(0x12151a);
  document.getElementById('view').appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.0));
  const sun = new THREE.DirectionalLight(0xffffff, 1.5);
  sun.position.set(1, 2, 3);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(60, window.innerWidth / window.innerHeight, 0.01, 1e7);
  const controls = new OrbitControls(camera, renderer.domElement);

  const tiles = new TilesRenderer('/tiles/tileset.json');
  // EXT_meshopt_compression contents (lodforge tiles --compress meshopt).
  tiles.registerPlugin(new GLTFExtensionsPlugin({ meshoptDecoder: MeshoptDecoder }));
  tiles.errorTarget = 16;
  tiles.setCamera(camera);
  tiles.setResolutionFromRenderer(camera, renderer);
  // Georeferenced tilesets: undo the root transform's rotation and ECEF translation.
  const pivot = new THREE.Group();
  pivot.add(tiles.group);
  scene.add(pivot);
  // Framed once the root is in: its bounding sphere, in the tileset's local frame (the root
  // transform undone, z-up turned to y-up).
  let framed = false;
  const frame = () => {
    const rootTransform = tiles.rootTileSet && tiles.rootTileSet.root && tiles.rootTileSet.root.transform;
    if (rootTransform) {
      tiles.group.matrixAutoUpdate = false;
      tiles.group.matrix.copy(new THREE.Matrix4().fromArray(rootTransform).invert());
    }
    pivot.rotation.x = -Math.PI / 2;  // 3D Tiles are z-up, three.js is y-up
    pivot.updateMatrixWorld(true);
    const sphere = new THREE.Sphere();
    if (!tiles.getBoundingSphere(sphere)) return false;
    sphere.applyMatrix4(tiles.group.matrixWorld);
    controls.target.copy(sphere.center);
    camera.position.copy(sphere.center)
      .add(new THREE.Vector3(0.6, 0.8, 1.2).normalize().multiplyScalar(sphere.radius * 2.2));
    camera.near = sphere.radius / 1000;
    camera.far = sphere.radius * 100;
    camera.updateProjectionMatrix();
    controls.update();
    return true;
  };
  tiles.addEventListener('load-model', () => { report.tilesLoaded += 1; });
  tiles.addEventListener('load-error', (e) => {
    report.failed.push(`${e.url}: ${e.error && e.error.message}`);
  });
  tiles.addEventListener('tiles-load-end', () => { if (framed && report.tilesLoaded > 0) report.loaded = true; });

  onScreenSpaceError((pixels) => { tiles.errorTarget = pixels; });
  window.addEventListener('resize', () => {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    tiles.setResolutionFromRenderer(camera, renderer);
  });
  const stats = document.getElementById('stats');
  renderer.setAnimationLoop(() => {
    if (!framed) framed = frame();
    controls.update();
    camera.updateMatrixWorld();
    tiles.update();
    renderer.render(scene, camera);
    const info = renderer.info;
    const points = info.render.points;
    stats.textContent =
      drawnSummary(tiles.visibleTiles.size, report.tilesLoaded, points, info.render.triangles) +
      ` · ${formatCount(info.memory.geometries)} geometries, ${formatBytes(tiles.lruCache.cachedBytes ?? 0)} cached`;
  });
}

try {
  main();
} catch (e) {
  report.error = String((e && e.stack) || e);
}
