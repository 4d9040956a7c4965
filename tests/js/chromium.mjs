// Debian's chromium, headless through playwright-core, as both browser tests use it: software
// WebGL (swiftshader), no background traffic, a throwaway profile.
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { chromium } from 'playwright-core';

// Returns { context, close }: close() closes the browser and removes its profile.
export async function launchChromium() {
  const profile = mkdtempSync(path.join(tmpdir(), 'lodforge-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport: { width: 800, height: 600 },
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--disable-background-networking', '--disable-component-update', '--disable-sync',
           '--no-first-run', '--disable-quic'],
  });
  const close = async () => {
    await context.close();
    rmSync(profile, { recursive: true, force: true });
  };
  return { context, close };
}

// Nothing may leave this machine: a request to any other host is aborted and reported.
export async function keepLocal(tab, report) {
  await tab.route('**/*', (route) => {
    const host = new URL(route.request().url()).hostname;
    if (host === '127.0.0.1' || host === 'localhost') return route.continue();
    report(`request to ${route.request().url()}`);
    return route.abort();
  });
}

// Shares of a screenshot's pixels (leaving out the element `skipId` covers, a stats panel, if
// given): `lit`, those that differ from the `background` colour ([r, g, b]; a summed difference
// over 30); `red` and `blue`, those clearly of that hue (a red and blue texture's colours, which
// untextured geometry, white or grey and lit, never shows, whatever the lighting).
async function pixelSharesOf(tab, png, background, skipId) {
  return tab.evaluate(async ({ data, background, skipId }) => {
    const image = new Image();
    image.src = 'data:image/png;base64,' + data;
    await image.decode();
    const canvas = document.createElement('canvas');
    canvas.width = image.width;
    canvas.height = image.height;
    const g = canvas.getContext('2d');
    g.drawImage(image, 0, 0);
    const skip = skipId ? document.getElementById(skipId).getBoundingClientRect() : null;
    const p = g.getImageData(0, 0, image.width, image.height).data;
    let lit = 0, red = 0, blue = 0, counted = 0;
    for (let y = 0; y < image.height; y++) {
      for (let x = 0; x < image.width; x++) {
        if (skip && x <= skip.right && y <= skip.bottom) continue;
        const i = 4 * (y * image.width + x);
        counted++;
        const difference = Math.abs(p[i] - background[0]) + Math.abs(p[i + 1] - background[1]) +
            Math.abs(p[i + 2] - background[2]);
        if (difference > 30) lit++;
        if (p[i] > 50 && p[i] > 2 * p[i + 1] && p[i] > 2 * p[i + 2]) red++;
        if (p[i + 2] > 50 && p[i + 2] > 2 * p[i] && p[i + 2] > 1.5 * p[i + 1]) blue++;
      }
    }
    return { lit: lit / counted, red: red / counted, blue: blue / counted };
  }, { data: png.toString('base64'), background, skipId });
}

export async function coverageOf(tab, png, background, skipId = null) {
  return (await pixelSharesOf(tab, png, background, skipId)).lit;
}

export async function hueSharesOf(tab, png, skipId = null) {
  const { red, blue } = await pixelSharesOf(tab, png, [0, 0, 0], skipId);
  return { red, blue };
}

// Share of pixels outside the element `skipId` that differ between two screenshots of a tab.
export async function differenceOf(tab, pngA, pngB, skipId = null) {
  return tab.evaluate(async ({ a, b, skipId }) => {
    const decode = async (data) => {
      const image = new Image();
      image.src = 'data:image/png;base64,' + data;
      await image.decode();
      const canvas = document.createElement('canvas');
      canvas.width = image.width;
      canvas.height = image.height;
      const g = canvas.getContext('2d');
      g.drawImage(image, 0, 0);
      return { pixels: g.getImageData(0, 0, image.width, image.height).data, width: image.width, height: image.height };
    };
    const [first, second] = [await decode(a), await decode(b)];
    const skip = skipId ? document.getElementById(skipId).getBoundingClientRect() : null;
    let changed = 0, counted = 0;
    for (let y = 0; y < first.height; y++) {
      for (let x = 0; x < first.width; x++) {
        if (skip && x <= skip.right && y <= skip.bottom) continue;
        const i = 4 * (y * first.width + x);
        counted++;
        const d = Math.abs(first.pixels[i] - second.pixels[i]) + Math.abs(first.pixels[i + 1] - second.pixels[i + 1]) +
            Math.abs(first.pixels[i + 2] - second.pixels[i + 2]);
        if (d > 30) changed++;
      }
    }
    return changed / counted;
  }, { a: pngA.toString('base64'), b: pngB.toString('base64'), skipId });
}
