// The pictures of docs/textures.md (not a test): a textured tileset in the three.js viewer at
// three screen-space errors (coarse, middle, fine), each once the tiles it asks for are drawn,
// and a close-up looking down on the middle (where a generated scan's atlases meet).
//   node texture-pictures.mjs LODFORGE TILESET_DIR OUT_DIR
import { spawn } from 'node:child_process';
import { writeFileSync } from 'node:fs';
import path from 'node:path';

import { keepLocal, launchChromium } from './chromium.mjs';

const [lodforge, tilesetDir, outDir] = process.argv.slice(2);
const server = spawn(lodforge, ['serve', tilesetDir, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
const port = await new Promise((resolve) => {
  let out = '';
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/http:\/\/127\.0\.0\.1:(\d+)\//);
    if (m) resolve(Number(m[1]));
  });
});
const { context, close } = await launchChromium();
try {
  const tab = await context.newPage();
  await keepLocal(tab, (p) => console.error(p));
  await tab.setViewportSize({ width: 800, height: 500 });
  await tab.goto(`http://127.0.0.1:${port}/three/`);
  await tab.waitForFunction(() => window.lodforge && window.lodforge.loaded, null, { timeout: 240000 });
  // Drawn once no tile has arrived for three seconds.
  const settle = async () => {
    let before = -1;
    for (;;) {
      await new Promise((r) => setTimeout(r, 3000));
      const now = await tab.evaluate(() => window.lodforge.tilesLoaded);
      if (now === before) return;
      before = now;
    }
  };
  for (const [name, sse] of [['coarse', 400], ['middle', 6], ['fine', 0.5]]) {
    await tab.evaluate((value) => {
      const slider = document.getElementById('sse');
      slider.max = Math.max(Number(slider.max), value);
      slider.min = Math.min(Number(slider.min), value);
      slider.step = 'any';
      slider.value = value;
      slider.dispatchEvent(new Event('input'));
    }, sse);
    await settle();
    const stats = await tab.evaluate(() => document.getElementById('stats').textContent);
    writeFileSync(path.join(outDir, `textures-${name}.png`), await tab.screenshot());
    console.log(`${name} (screen-space error ${sse}): ${stats}`);
  }
  // A seam close-up: straight down on the middle of the model from CLOSE_UP (default 27) model
  // units, at the finest screen-space error. The middle of a generated scan with 4 x 4 atlases
  // is where four of them meet, and where the octree splits its leaves.
  const distance = Number(process.env.CLOSE_UP || 27);
  if (!(await tab.evaluate((d) => window.lodforge.lookDownOnMiddle(d), distance)))
    throw new Error('no surface under the middle of the model');
  await settle();
  writeFileSync(path.join(outDir, 'textures-seam.png'), await tab.screenshot());
  console.log(`seam close-up from ${distance}: ${await tab.evaluate(() => document.getElementById('stats').textContent)}`);
} finally {
  await close();
  server.kill();
}
