// lodforge's implicit tilesets keep each tile's own geometric error and tight box as tile
// metadata (TILE_GEOMETRIC_ERROR, TILE_BOUNDING_BOX, in the subtree's tile property table);
// 3d-tiles-renderer's ImplicitTilingPlugin reads neither (it halves the root's error per level
// and cuts the root's box in eight). This plugin, registered before it, reads them from each
// subtree as it arrives and gives them to the tiles that plugin makes from it.
export class ImplicitMetadataPlugin {
  constructor() {
    this.name = 'LODFORGE_IMPLICIT_METADATA';
    this.values = new Map(); // "level/x/y/z" -> { error, box }
  }

  init(tiles) {
    this.tiles = tiles;
  }

  // Reads the metadata and lets ImplicitTilingPlugin parse the subtree (null: not handled).
  parseTile(buffer, tile, extension) {
    if (/^subtree$/i.test(extension)) readSubtreeMetadata(buffer, tile, this.values);
    return null;
  }

  preprocessNode(tile) {
    if (tile.implicitTiling || tile.__level === undefined) return;
    const value = this.values.get(`${tile.__level}/${tile.__x}/${tile.__y}/${tile.__z}`);
    if (!value) return;
    tile.geometricError = value.error;
    tile.boundingVolume = { box: value.box };
  }
}

// x, y, z of a Morton index (bits interleaved x, y, z from the lowest).
function deinterleave(m, level) {
  let x = 0, y = 0, z = 0;
  for (let b = 0; b < level; b++) {
    x |= ((m >> (3 * b)) & 1) << b;
    y |= ((m >> (3 * b + 1)) & 1) << b;
    z |= ((m >> (3 * b + 2)) & 1) << b;
  }
  return [x, y, z];
}

function readSubtreeMetadata(buffer, tile, values) {
  const view = new DataView(buffer);
  const jsonLength = view.getUint32(8, true);
  const binaryLength = view.getUint32(16, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 24, jsonLength)));
  const binary = buffer.slice(24 + jsonLength, 24 + jsonLength + binaryLength);
  if (json.tileMetadata === undefined) return;
  const table = json.propertyTables[json.tileMetadata];
  // Another writer's subtree (lodforge serve takes any tileset): the plugin's defaults stand.
  if (!table.properties.geometricError || !table.properties.boundingBox) return;
  const valuesOf = (name) => {
    const v = json.bufferViews[table.properties[name].values];
    return new Float64Array(binary.slice(v.byteOffset, v.byteOffset + v.byteLength));
  };
  const errors = valuesOf('geometricError');
  const boxes = valuesOf('boundingBox');
  const availability = json.tileAvailability;
  const bits = availability.bitstream === undefined ? null : (() => {
    const v = json.bufferViews[availability.bitstream];
    return new Uint8Array(binary, v.byteOffset, v.byteLength);
  })();
  const available = (i) => (bits ? ((bits[i >> 3] >> (i & 7)) & 1) === 1 : availability.constant === 1);
  const levels = tile.__implicitRoot.implicitTiling.subtreeLevels;
  const availableLevels = tile.__implicitRoot.implicitTiling.availableLevels;
  let row = 0;
  // Tiles are in the property table in the order of their availability bits.
  for (let level = 0, first = 0; level < levels && tile.__level + level < availableLevels; level++) {
    const count = 8 ** level;
    for (let m = 0; m < count; m++) {
      if (!available(first + m)) continue;
      const [x, y, z] = deinterleave(m, level);
      const key = `${tile.__level + level}/${(tile.__x << level) | x}/${(tile.__y << level) | y}/${(tile.__z << level) | z}`;
      values.set(key, { error: errors[row], box: Array.from(boxes.subarray(12 * row, 12 * row + 12)) });
      row++;
    }
    first += count;
  }
}
