// CesiumJS viewer for the tileset lodforge serve hands out at /tiles/: no Ion token, no online
// imagery or terrain (no globe), flies to the tileset, shows what is loaded and drawn, and
// lets the screen-space error be chosen. window.lodforge reports to tests.
import { drawnSummary, formatBytes, onScreenSpaceError } from '../format.js';

const Cesium = window.Cesium;
const report = (window.lodforge = { loaded: false, failed: [], error: null, tilesLoaded: 0 });

async function main() {
  const viewer = new Cesium.Viewer('view', {
    baseLayer: false, baseLayerPicker: false, geocoder: false, timeline: false, animation: false,
    homeButton: false, sceneModePicker: false, navigationHelpButton: false, fullscreenButton: false,
    infoBox: false, selectionIndicator: false,
    terrainProvider: new Cesium.EllipsoidTerrainProvider(), skyBox: false, skyAtmosphere: false,
  });
  // No imagery and no terrain: the globe would be a blank ball; the model alone is shown.
  viewer.scene.globe.show = false;
  viewer.scene.backgroundColor = Cesium.Color.fromCssColorString('#12151a');
  const tileset = await Cesium.Cesium3DTileset.fromUrl('/tiles/tileset.json', {
    maximumScreenSpaceError: 16,
    // Point tilesets: points grow with their tile's geometric error, so a coarse tile is not a
    // sprinkle of single pixels (meshes are not affected).
    pointCloudShading: { attenuation: true, maximumAttenuation: 6 },
  });
  viewer.scene.primitives.add(tileset);
  tileset.tileFailed.addEventListener((e) => report.failed.push(`${e.url}: ${e.message}`));
  tileset.tileLoad.addEventListener(() => { report.tilesLoaded += 1; });
  tileset.allTilesLoaded.addEventListener(() => { report.loaded = true; });
  // What is drawn this frame: tiles, and their triangles or points.
  let drawn = { tiles: 0, triangles: 0, points: 0 };
  tileset.tileVisible.addEventListener((tile) => {
    drawn.tiles += 1;
    const content = tile.content;
    drawn.triangles += content.trianglesLength ?? 0;
    drawn.points += content.pointsLength ?? 0;
  });
  const stats = document.getElementById('stats');
  viewer.scene.postRender.addEventListener(() => {
    stats.textContent =
      drawnSummary(drawn.tiles, report.tilesLoaded, drawn.points, drawn.triangles) +
      ` · ${formatBytes(tileset.totalMemoryUsageInBytes)} in tiles`;
    report.drawn = drawn;
    drawn = { tiles: 0, triangles: 0, points: 0 };
  });
  onScreenSpaceError((pixels) => { tileset.maximumScreenSpaceError = pixels; });
  await viewer.flyTo(tileset, { duration: 0 });
}

main().catch((e) => { report.error = String((e && e.stack) || e); });
