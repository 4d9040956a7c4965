// three.js viewer with NASA-AMMOS 3d-tiles-renderer for the tileset at /tiles/: the tileset is
// moved to the origin (a georeferenced one sits 6,000 km away in ECEF) and turned so its local
// up is +y, an orbit camera frames it; stats and a screen-space-error slider as on the Cesium
// page. window.lodforge reports to tests.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { MeshoptDecoder } from 'three/examples/jsm/libs/meshopt_decoder.module.js';
import { TilesRenderer } from '3d-tiles-renderer';
import { GLTFExtensionsPlugin, ImplicitTilingPlugin } from '3d-tiles-renderer/plugins';
import { ImplicitMetadataPlugin } from './implicit_metadata.js';
import { drawnSummary, formatBytes, formatCount, onScreenSpaceError } from '../format.js';
import { boundsOf, loadParts, partsPanel } from '../parts_panel.js';
import { classColor, colorModes, colorPanel, intensityGrey, ramp } from '../point_colors.js';

const report = (window.lodforge = { loaded: false, failed: [], error: null, tilesLoaded: 0, frames: 0 });

// The view is drawn on demand, as the CesiumJS page is: a frame when something changed (the
// camera, a tile loaded, a colour or a part's state) and every frame while tiles load; an idle
// view costs no GPU time.
let frameWanted = true;
function requestFrame() {
  frameWanted = true;
}

// Point tiles coloured by a LAS field: each loaded Points object keeps its own colours and is
// recoloured on the CPU (RGBA; a hidden class gets alpha 0, which alphaTest discards).
const RETURN_COLORS = [[0.9, 0.2, 0.15], [0.95, 0.6, 0.1], [0.95, 0.9, 0.2], [0.3, 0.8, 0.3], [0.2, 0.5, 0.95]];
const colouring = { mode: null, hidden: new Set(), classes: new Set(), heights: null, intensityMax: 1,
                    panel: null, points: new Set() };

function recolour(points) {
  const g = points.geometry;
  const color = g.getAttribute('color');
  const rgb = points.userData.rgb;
  const cls = g.getAttribute('_classification');
  const intensity = g.getAttribute('_intensity');
  const returns = g.getAttribute('_return_number');
  const position = g.getAttribute('position');
  const p = new THREE.Vector3();
  for (let i = 0; i < color.count; ++i) {
    let c = [1, 1, 1];
    const mode = colouring.mode;
    if (mode === 'rgb' && rgb) c = [rgb[4 * i] / 255, rgb[4 * i + 1] / 255, rgb[4 * i + 2] / 255];
    else if (mode === 'classification' && cls) c = classColor(cls.getX(i));
    else if (mode === 'intensity' && intensity) c = new Array(3).fill(intensityGrey(intensity.getX(i) / colouring.intensityMax));
    else if (mode === 'return number' && returns) c = RETURN_COLORS[Math.min(Math.max(returns.getX(i), 1), 5) - 1];
    else if (mode === 'elevation' && colouring.heights) {
      p.fromBufferAttribute(position, i).applyMatrix4(points.matrixWorld);
      c = ramp((p.y - colouring.heights[0]) / (colouring.heights[1] - colouring.heights[0]));
    }
    const hidden = cls && colouring.hidden.has(cls.getX(i));
    const out = color.array;  // Uint8, normalised: written as bytes
    out[4 * i] = Math.round(c[0] * 255);
    out[4 * i + 1] = Math.round(c[1] * 255);
    out[4 * i + 2] = Math.round(c[2] * 255);
    out[4 * i + 3] = hidden ? 0 : 255;
  }
  color.needsUpdate = true;
}

// A colour setting changed (a tile's first colouring is drawn with its load's frame).
function recolourAll() {
  for (const points of colouring.points) recolour(points);
  requestFrame();
}

// A tile's Points, as they load: RGBA colours to write into, the original RGB kept, the
// classes and intensities it holds noted; the panel made for the first.
function preparePoints(points) {
  const g = points.geometry;
  const names = Object.keys(g.attributes).map((n) => (n === 'color' ? 'COLOR_0' : n.toUpperCase()));
  const old = g.getAttribute('color');
  let rgb = null;
  if (old) {  // COLOR_0 (normalised: getX and friends give 0..1)
    rgb = new Uint8Array(old.count * 4);
    for (let i = 0; i < old.count; ++i) {
      rgb[4 * i] = Math.round(old.getX(i) * 255);
      rgb[4 * i + 1] = Math.round(old.getY(i) * 255);
      rgb[4 * i + 2] = Math.round(old.getZ(i) * 255);
    }
  }
  points.userData.rgb = rgb;
  g.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(g.getAttribute('position').count * 4), 4, true));
  points.material.vertexColors = true;
  points.material.alphaTest = 0.5;
  points.material.needsUpdate = true;
  const cls = g.getAttribute('_classification');
  let added = false;
  if (cls) for (let i = 0; i < cls.count; ++i) {
    if (!colouring.classes.has(cls.getX(i))) { colouring.classes.add(cls.getX(i)); added = true; }
  }
  const intensity = g.getAttribute('_intensity');
  if (intensity) for (let i = 0; i < intensity.count; ++i)
    colouring.intensityMax = Math.max(colouring.intensityMax, intensity.getX(i) > 255 ? 65535 : 255);
  if (!colouring.panel) {
    const modes = colorModes(names);
    colouring.mode = modes[0];
    report.colorModes = modes;
    colouring.panel = colorPanel(modes, colouring.classes, (mode) => {
      colouring.mode = mode;
      recolourAll();
    }, (value, visible) => {
      if (visible) colouring.hidden.delete(value); else colouring.hidden.add(value);
      recolourAll();
    });
  } else if (added) {
    colouring.panel.addClasses();
  }
  colouring.points.add(points);
  points.updateMatrixWorld(true);
  recolour(points);
}

report.setColorMode = (mode) => colouring.panel && colouring.panel.setMode(mode);
report.setClassVisible = (value, visible) => {
  const box = document.querySelector(`#legend input[data-class="${value}"]`);
  if (visible) colouring.hidden.delete(value); else colouring.hidden.add(value);
  if (box) box.checked = visible;
  recolourAll();
};
report.classes = () => [...colouring.classes];

// Tilesets of parts: each mesh's "_feature_id_0" attribute gives a vertex's row in its tile's
// property table; the table's "id" column (read by partIdsPlugin as the tile's glTF is parsed)
// turns rows into parts of parts.json. Highlighting and hiding recolour the vertices (alpha 0 is
// discarded by alphaTest; a triangle's corners are all of one part).
const HIGHLIGHT = [255, 210, 31];
const partState = { parts: null, highlighted: new Set(), hidden: new Set(), meshes: new Set() };

// A GLTFLoader plugin: the property table's "id" column of a tile, from the bytes being parsed
// (not downloaded a second time), kept as the tile scene's userData.partIds.
const partIdsPlugin = (parser) => ({
  name: 'lodforge_part_ids',
  async afterRoot(result) {
    const metadata = parser.json.extensions && parser.json.extensions.EXT_structural_metadata;
    if (!metadata || !metadata.propertyTables) return;
    const view = metadata.propertyTables[0].properties.id.values;
    result.scene.userData.partIds = new Uint32Array(await parser.getDependency('bufferView', view));
  },
});

// A part's CAD layers as parts.json names them ('' for none).
function partLayer(id) {
  const part = partState.parts && partState.parts.parts[id];
  return (part && part.layer) || '';
}

function partOfVertex(mesh, vertex) {
  const rows = mesh.geometry.getAttribute('_feature_id_0');
  const ids = mesh.userData.partIds;
  return rows && ids ? ids[Math.round(rows.getX(vertex))] : null;
}

function recolourParts(mesh) {
  const g = mesh.geometry;
  const color = g.getAttribute('color');
  const rgb = mesh.userData.rgb;
  for (let i = 0; i < color.count; ++i) {
    const part = partOfVertex(mesh, i);
    const c = partState.highlighted.has(part) ? HIGHLIGHT : rgb ? [rgb[4 * i], rgb[4 * i + 1], rgb[4 * i + 2]] : [255, 255, 255];
    // Hidden parts get alpha 0 (discarded by alphaTest); the others keep theirs (glass).
    const alpha = partState.hidden.has(part) ? 0 : rgb ? rgb[4 * i + 3] : 255;
    color.array.set([c[0], c[1], c[2], alpha], 4 * i);
  }
  color.needsUpdate = true;
}

// A tile's meshes, as they load: RGBA colours to write into (the original kept), its part ids.
function prepareParts(scene) {
  const ids = scene.userData.partIds;
  if (!ids) return;
  scene.traverse((mesh) => {
    if (!mesh.isMesh || !mesh.geometry.getAttribute('_feature_id_0')) return;
    const g = mesh.geometry;
    const old = g.getAttribute('color');
    const count = g.getAttribute('position').count;
    let rgb = null;
    if (old) {
      rgb = new Uint8Array(count * 4);
      for (let i = 0; i < count; ++i) {
        rgb[4 * i] = Math.round(old.getX(i) * 255);
        rgb[4 * i + 1] = Math.round(old.getY(i) * 255);
        rgb[4 * i + 2] = Math.round(old.getZ(i) * 255);
        rgb[4 * i + 3] = old.itemSize === 4 ? Math.round(old.getW(i) * 255) : 255;
      }
    }
    mesh.userData.rgb = rgb;
    mesh.userData.partIds = ids;
    g.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(count * 4), 4, true));
    mesh.material = mesh.material.clone();
    mesh.material.vertexColors = true;
    mesh.material.alphaTest = 0.01;  // hidden parts only: glass at alpha 0.12 stays
    mesh.material.needsUpdate = true;
    partState.meshes.add(mesh);
    recolourParts(mesh);
  });
}

function addParts(parts, tiles, camera, controls, renderer, pivot) {
  partState.parts = parts;
  const restyle = () => {
    for (const mesh of partState.meshes) recolourParts(mesh);
    requestFrame();
  };
  const raycaster = new THREE.Raycaster();
  // The part drawn at a pixel (CSS pixels of the canvas): the nearest hit of a part not hidden.
  const partAt = (x, y) => {
    const r = renderer.domElement.getBoundingClientRect();
    raycaster.setFromCamera(new THREE.Vector2((x / r.width) * 2 - 1, -(y / r.height) * 2 + 1), camera);
    for (const hit of raycaster.intersectObject(tiles.group, true)) {
      if (!hit.face || !partState.meshes.has(hit.object)) continue;
      const part = partOfVertex(hit.object, hit.face.a);
      if (part !== null && !partState.hidden.has(part)) return part;
    }
    return null;
  };
  const panel = partsPanel(parts, {
    highlight: (ids) => { partState.highlighted = new Set(ids); restyle(); },
    hide: (ids) => { partState.hidden = new Set(ids); restyle(); },
    flyTo: (ids) => {
      const b = boundsOf(parts, ids);
      if (!b) return;
      const corners = [new THREE.Vector3(b[0], b[1], b[2]), new THREE.Vector3(b[3], b[4], b[5])]
        .map((p) => p.applyMatrix4(pivot.matrixWorld));
      const centre = corners[0].clone().add(corners[1]).multiplyScalar(0.5);
      const radius = Math.max(corners[0].distanceTo(corners[1]) / 2, 1e-6);
      const direction = camera.position.clone().sub(controls.target).normalize();
      controls.target.copy(centre);
      camera.position.copy(centre).add(direction.multiplyScalar(radius * 2.5));
      camera.near = radius / 1000;
      camera.updateProjectionMatrix();
      controls.update();
      requestFrame();
    },
  });
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;  // a drag
    const r = renderer.domElement.getBoundingClientRect();
    panel.picked(partAt(e.clientX - r.left, e.clientY - r.top));
  });
  report.parts = {
    count: parts.parts.length,
    pick: (x, y) => {
      const id = partAt(x, y);
      if (id === null) return null;
      const part = parts.parts[id];
      return { id, name: part.name, path: part.path, layer: partLayer(id),
               highlighted: partState.highlighted.has(id) };
    },
    find: (text) => panel.find(text),
    isolate: (id) => panel.hide(parts.parts.map((p) => p.id).filter((i) => i !== id)),
    hide: (id) => panel.hide([id]),
    showAll: () => panel.showAll(),
    shown: () => panel.shown(),
    layers: () => panel.layers(),
    setLayer: (name, shown) => panel.setLayer(name, shown),
    idle: () => tiles.stats.downloading === 0 && tiles.stats.parsing === 0,
  };
}

// The tile whose volume frames the view: the root, or for an implicit tileset (its root volume
// is the whole octree cube) the root's own content tile once the first subtree is in, whose
// volume is the tight box of the subtree's metadata.
function framingTile(tiles) {
  const root = tiles.rootTileSet && tiles.rootTileSet.root;
  const tile = root && root.implicitTiling ? root.children[0] : root;
  return tile && tile.cached && tile.cached.boundingVolume ? tile : null;
}

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
  controls.addEventListener('change', requestFrame);

  const tiles = new TilesRenderer('/tiles/tileset.json');
  // EXT_meshopt_compression contents (lodforge tiles --compress meshopt).
  tiles.registerPlugin(new GLTFExtensionsPlugin({ meshoptDecoder: MeshoptDecoder, plugins: [partIdsPlugin] }));
  // Implicit tilesets (lodforge tiles --implicit-tiling): the metadata first, then the subtrees.
  tiles.registerPlugin(new ImplicitMetadataPlugin());
  tiles.registerPlugin(new ImplicitTilingPlugin());
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
    const tile = framingTile(tiles);
    if (!tile) return false;
    tile.cached.boundingVolume.getSphere(sphere);
    sphere.applyMatrix4(tiles.group.matrixWorld);
    controls.target.copy(sphere.center);
    camera.position.copy(sphere.center)
      .add(new THREE.Vector3(0.6, 0.8, 1.2).normalize().multiplyScalar(sphere.radius * 2.2));
    camera.near = sphere.radius / 1000;
    camera.far = sphere.radius * 100;
    camera.updateProjectionMatrix();
    controls.update();
    colouring.heights = [sphere.center.y - sphere.radius, sphere.center.y + sphere.radius];
    return true;
  };
  // For tests: the framing tile's bounding box corners in CSS pixels (null: behind the camera).
  report.rootCorners = () => {
    const root = tiles.rootTileSet && tiles.rootTileSet.root;
    const tile = framingTile(tiles);
    const box = tile && tile.boundingVolume && tile.boundingVolume.box;
    if (!box) return [];
    const toTiles = root.transform ? new THREE.Matrix4().fromArray(root.transform) : new THREE.Matrix4();
    const corners = [];
    for (let i = 0; i < 8; ++i) {
      const corner = new THREE.Vector3(box[0], box[1], box[2]);
      for (let a = 0; a < 3; ++a) {
        const sign = (i >> a) & 1 ? 1 : -1;
        corner.add(new THREE.Vector3(box[3 + 3 * a], box[4 + 3 * a], box[5 + 3 * a]).multiplyScalar(sign));
      }
      const ndc = corner.applyMatrix4(toTiles).applyMatrix4(tiles.group.matrixWorld).project(camera);
      corners.push(ndc.z > 1 ? null : [((ndc.x + 1) / 2) * window.innerWidth, ((1 - ndc.y) / 2) * window.innerHeight]);
    }
    return corners;
  };
  // For pictures: the camera `distance` above the surface point under the middle of the model
  // (found by a ray straight down), looking down on it; false when the ray meets nothing.
  report.lookDownOnMiddle = (distance) => {
    const sphere = new THREE.Sphere();
    if (!tiles.getBoundingSphere(sphere)) return false;
    sphere.applyMatrix4(tiles.group.matrixWorld);
    const top = sphere.center.clone().add(new THREE.Vector3(0, sphere.radius * 2, 0));
    const hit = new THREE.Raycaster(top, new THREE.Vector3(0, -1, 0)).intersectObject(tiles.group, true)[0];
    if (!hit) return false;
    controls.target.copy(hit.point);
    // A hair off vertical: the orbit controls need a view direction apart from their up.
    camera.position.copy(hit.point).add(new THREE.Vector3(0, distance, distance * 1e-3));
    controls.update();
    requestFrame();
    return true;
  };
  for (const event of ['load-tile-set', 'load-model', 'dispose-model', 'tiles-load-start', 'tiles-load-end'])
    tiles.addEventListener(event, requestFrame);
  tiles.addEventListener('load-model', (e) => {
    report.tilesLoaded += 1;
    e.scene.traverse((o) => { if (o.isPoints) preparePoints(o); });
    prepareParts(e.scene);
  });
  tiles.addEventListener('dispose-model', (e) => {
    e.scene.traverse((o) => { colouring.points.delete(o); partState.meshes.delete(o); });
  });
  tiles.addEventListener('load-error', (e) => {
    report.failed.push(`${e.url}: ${e.error && e.error.message}`);
  });
  tiles.addEventListener('tiles-load-end', () => { if (framed && report.tilesLoaded > 0) report.loaded = true; });
  loadParts('/tiles/').then((parts) => {
    if (!parts) return;
    addParts(parts, tiles, camera, controls, renderer, pivot);
  }).catch((error) => { report.error = String(error); });

  onScreenSpaceError((pixels) => { tiles.errorTarget = pixels; requestFrame(); });
  window.addEventListener('resize', () => {
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(window.innerWidth, window.innerHeight);
    tiles.setResolutionFromRenderer(camera, renderer);
    requestFrame();
  });
  const stats = document.getElementById('stats');
  let cached = 0;  // tiles.stats.inCache at the last frame
  renderer.setAnimationLoop(() => {
    // Loading, or tiles left the cache (a full cache holds back the tiles waiting for it until
    // the next update, and dropping a tile without a model fires no event).
    const loading = tiles.stats.downloading > 0 || tiles.stats.parsing > 0 ||
                    tiles.stats.inCache !== cached;
    // A tileset that failed to load has nothing to frame: it waits like an idle view.
    if (!frameWanted && !loading && (framed || report.failed.length > 0)) return;
    frameWanted = false;
    cached = tiles.stats.inCache;
    if (!framed) framed = frame();
    controls.update();
    camera.updateMatrixWorld();
    tiles.update();
    renderer.render(scene, camera);
    report.frames += 1;
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
