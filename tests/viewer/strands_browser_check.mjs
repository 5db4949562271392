// Drives strands viewer pages written by flexkin::WriteStrandsViewerHtml in headless Chromium
// (the system's Debian package, software-rendered WebGL, through playwright-core from tools/node)
// and checks that they work offline, draw, play, scrub and answer the keys, and how fast they
// play. Run by tests/strands_viewer_test.cc:
//   node tests/viewer/strands_browser_check.mjs TOOLS_NODE_DIR OUT_DIR PAGE.html...
// Next to PAGE.html, PAGE.points.json may list points of the strand file ([{frame, point, xyz}],
// frame and point as embedded): the page's decoded points must match them within its precision.
// Writes screenshots to OUT_DIR, prints one line per check and the frame rate per page
// ("fps ..."), and exits with 1 if any check failed. Environment: FLEXKIN_CHROMIUM overrides the
// browser (default /usr/bin/chromium); FLEXKIN_MIN_STRANDS_FPS the frame-rate floor (default 30).
import { createRequire } from 'node:module';
import { existsSync, readFileSync } from 'node:fs';
import { basename, join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [toolsDir, outDir, ...pages] = process.argv.slice(2);
if (!toolsDir || !outDir || pages.length === 0) {
  console.error('usage: node strands_browser_check.mjs TOOLS_NODE_DIR OUT_DIR PAGE.html...');
  process.exit(2);
}
const chromiumPath = process.env.FLEXKIN_CHROMIUM || '/usr/bin/chromium';
// The page must keep drawing while it plays: WebGL lines on a software renderer draw 2.4 to 3.3
// fps here, the page's own renderer 40 to 48. The frame rate itself is a measurement
// (bench/viewer_fps.sh, 30 fps the target), not a test's pass mark: a loaded machine halves it.
const minFps = Number(process.env.FLEXKIN_MIN_STRANDS_FPS || 5);
if (!existsSync(chromiumPath)) {
  console.error(`Chromium not found at ${chromiumPath}; run scripts/install-deps.sh`);
  process.exit(3);
}
let chromium;
try {
  ({ chromium } = createRequire(join(resolve(toolsDir), 'package.json'))('playwright-core'));
} catch (e) {
  console.error(`playwright-core not found in ${toolsDir}/node_modules; run scripts/install-deps.sh`);
  process.exit(3);
}

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
}
const sleep = (ms) => new Promise((done) => setTimeout(done, ms));
const viewer = (page, what) => page.evaluate((w) => window.flexkinStrandsViewer[w], what);
const picture = (page) => page.evaluate(() => window.flexkinStrandsViewer.pixels());

async function checkPage(browser, file) {
  const name = basename(file, '.html');
  const url = pathToFileURL(resolve(file)).href;
  // The canvas gets about 1310 x 800 pixels of this (the panel and the controls take the rest).
  const context = await browser.newContext({ viewport: { width: 1600, height: 900 } });
  const requests = [];
  await context.route('**/*', (route) => {
    if (route.request().url() === url) return route.continue();
    requests.push(route.request().url());
    return route.abort();
  });
  const page = await context.newPage();
  const errors = [];
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`page error: ${e.message}`));
  page.on('request', (r) => { if (r.url() !== url) requests.push(r.url()); });
  page.on('requestfailed', (r) => errors.push(`request failed: ${r.url()}`));

  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.flexkinStrandsViewer &&
      (window.flexkinStrandsViewer.error || window.flexkinStrandsViewer.stats.draws > 0),
      null, { timeout: 120000 });
  const info = await page.evaluate(() => {
    const v = window.flexkinStrandsViewer;
    const c = document.getElementById('view');
    return { error: v.error, dim: v.dim, numFrames: v.numFrames, numStrands: v.numStrands,
             numPoints: v.numPoints, width: c.width, height: c.height };
  });
  check(!info.error, `${name}: decoded and drawn in ${Date.now() - t0} ms ${info.error || ''}`);
  if (info.error) return;
  const n = info.numFrames;
  console.log(`--- ${name}: ${info.dim}D, ${info.numStrands} strands, ` +
              `${info.numPoints - info.numStrands} links, ${n} frames, canvas ${info.width} x ` +
              `${info.height}`);
  check(await viewer(page, 'playing'), `${name}: plays on opening (autoplay)`);

  const expected = file.replace(/\.html$/, '.points.json');
  if (existsSync(expected)) {
    const points = JSON.parse(readFileSync(expected, 'utf8'));
    const worst = await page.evaluate((points) => {
      const v = window.flexkinStrandsViewer;
      const precision = JSON.parse(document.getElementById('flexkin-strands').textContent).precision;
      let error = 0;
      for (const p of points) {
        const got = v.point(p.frame, p.point);
        for (let c = 0; c < p.xyz.length; ++c) error = Math.max(error, Math.abs(got[c] - p.xyz[c]));
      }
      return { error, precision };
    }, points);
    check(worst.error <= worst.precision * (1 + 1e-9) + 1e-12,
          `${name}: ${points.length} decoded points within the precision ${worst.precision} ` +
          `of the file's (largest error ${worst.error})`);
  }

  // Pause with the space bar; the picture then stays still.
  await page.locator('#view').focus();
  await page.keyboard.press('Space');
  check(!(await viewer(page, 'playing')), `${name}: space pauses`);
  await page.keyboard.press('Home');
  check((await viewer(page, 'frame')) === 0, `${name}: Home goes to the first frame`);
  const still1 = await picture(page);
  await sleep(300);
  const still2 = await picture(page);
  check(still1.hash === still2.hash, `${name}: paused picture stays still`);
  check(still1.drawnFraction > 0.002 && still1.colors > 8,
        `${name}: canvas not blank (${(100 * still1.drawnFraction).toFixed(1)}% drawn, ` +
        `${still1.colors} colours)`);
  await page.screenshot({ path: join(outDir, `${name}-first.png`) });

  // Play with the button: the frame and the picture change.
  await page.click('#play');
  await sleep(600);
  const f1 = await viewer(page, 'frame');
  const moving = await picture(page);
  check(f1 !== 0 && moving.hash !== still1.hash,
        `${name}: playing moves on (frame 0 -> ${f1}) and changes the picture`);
  await page.screenshot({ path: join(outDir, `${name}-playing.png`) });
  await page.click('#play');
  check(!(await viewer(page, 'playing')) && (await page.textContent('#play')) === 'Play',
        `${name}: play button pauses`);

  // Scrub with the timeline; the counter says where we are. Then the keys.
  const k = Math.floor(0.37 * (n - 1));
  await page.evaluate((value) => {
    const t = document.getElementById('timeline');
    t.value = String(value);
    t.dispatchEvent(new Event('input', { bubbles: true }));
  }, k);
  const counter = await page.textContent('#counter');
  check((await viewer(page, 'frame')) === k && counter.includes(`frame ${k + 1} / ${n}`),
        `${name}: scrubbed to frame ${k + 1}, counter says "${counter}"`);
  const box = await page.locator('#timeline').boundingBox();
  await page.mouse.click(box.x + 0.75 * box.width, box.y + box.height / 2);
  const clicked = await viewer(page, 'frame');
  check(Math.abs(clicked - 0.75 * (n - 1)) <= 0.05 * n + 1,
        `${name}: clicking the timeline at 75% goes to frame ${clicked} of ${n}`);
  await page.locator('#view').focus();
  await page.keyboard.press('ArrowRight');
  check((await viewer(page, 'frame')) === Math.min(n - 1, clicked + 1), `${name}: right arrow steps on`);
  await page.keyboard.press('ArrowLeft');
  check((await viewer(page, 'frame')) === clicked, `${name}: left arrow steps back`);
  await page.keyboard.press('End');
  check((await viewer(page, 'frame')) === n - 1, `${name}: End goes to the last frame`);
  await page.keyboard.press('Home');

  // Orbit (3D) or pan (2D), zoom, and R gives the first picture back.
  const home = await picture(page);
  const canvasBox = await page.locator('#view').boundingBox();
  const cx = canvasBox.x + canvasBox.width / 2, cy = canvasBox.y + canvasBox.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await page.mouse.move(cx + 90, cy + 40, { steps: 5 });
  await page.mouse.up();
  const dragged = await picture(page);
  check(dragged.hash !== home.hash, `${name}: dragging ${info.dim === 2 ? 'pans' : 'orbits'}`);
  await page.mouse.wheel(0, -300);
  await sleep(50);
  const zoomed = await picture(page);
  check(zoomed.hash !== dragged.hash, `${name}: the wheel zooms`);
  await page.screenshot({ path: join(outDir, `${name}-moved.png`) });
  await page.locator('#view').focus();
  await page.keyboard.press('r');
  check((await picture(page)).hash === home.hash, `${name}: R restores the view`);

  // Frame rate: playing from the first frame at a speed at which every display frame shows
  // another moment of the motion (blending between stored frames), so every animation frame
  // draws a new picture. Counted: pictures drawn that show a new moment, per second.
  await page.selectOption('#speed', '1');
  await page.click('#play');
  await sleep(1000);  // settle
  await page.evaluate(() => {
    Object.assign(window.flexkinStrandsViewer.stats,
                  { ticks: 0, draws: 0, newPictures: 0, drawMs: 0, maxDrawMs: 0 });
  });
  const t1 = Date.now();
  await sleep(4000);
  const perf = await page.evaluate(() => ({ ...window.flexkinStrandsViewer.stats }));
  const seconds = (Date.now() - t1) / 1000;
  const fps = perf.newPictures / seconds;
  console.log(`${name}: fps ${fps.toFixed(1)} (${perf.newPictures} new pictures in ` +
              `${seconds.toFixed(2)} s, ${(perf.ticks / seconds).toFixed(1)} animation ` +
              `callbacks/s, mean draw call ${(perf.drawMs / Math.max(1, perf.draws)).toFixed(2)} ` +
              `ms of the main thread, canvas ${info.width} x ${info.height})`);
  const renderer = await viewer(page, 'renderer');
  if (info.numPoints - info.numStrands >= 320000) {
    check(fps >= minFps, `${name}: keeps drawing while playing (${fps.toFixed(1)} >= ${minFps} fps, ${renderer} renderer)`);
    // Software WebGL here: the page draws the many links itself.
    check(renderer === 'software', `${name}: the software renderer is chosen (${renderer})`);
  }

  // The groom's colliders beside the scalp (a neck): both renderers draw them in the colliders'
  // grey, and hiding the scalp hides them too.
  const colliders = await page.evaluate(() => (JSON.parse(
      document.getElementById('flexkin-strands').textContent).colliders || []).length);
  if (colliders > 0) {
    await page.click('#play');
    await page.keyboard.press('Home');
    for (const name2 of ['webgl', 'software']) {
      await page.evaluate((r) => window.flexkinStrandsViewer.setRenderer(r), name2);
      const shown = await picture(page);
      await page.click('#scalp');
      const hidden = await picture(page);
      await page.click('#scalp');
      check(shown.colliderFraction > 0.003 && hidden.colliderFraction < 0.2 * shown.colliderFraction,
            `${name}: ${colliders} collider(s) drawn by the ${name2} renderer ` +
            `(${(100 * shown.colliderFraction).toFixed(2)}% of the picture; ` +
            `${(100 * hidden.colliderFraction).toFixed(2)}% with the scalp hidden)`);
      await page.screenshot({ path: join(outDir, `${name}-colliders-${name2}.png`) });
    }
    await page.evaluate((r) => window.flexkinStrandsViewer.setRenderer(r), renderer);
    await page.click('#play');
  }

  // G switches renderers; both draw the same strands, so about as many pixels.
  await page.click('#play');
  await page.keyboard.press('Home');
  await page.locator('#view').focus();
  const before = await picture(page);
  await page.keyboard.press('g');
  const other = await viewer(page, 'renderer');
  const switched = await picture(page);
  check(other !== renderer && switched.colors > 8 &&
        Math.abs(switched.drawnFraction - before.drawnFraction) <= 0.25 * before.drawnFraction,
        `${name}: G switches ${renderer} -> ${other}; drawn ${(100 * before.drawnFraction).toFixed(1)}% ` +
        `-> ${(100 * switched.drawnFraction).toFixed(1)}% of the canvas`);
  await page.screenshot({ path: join(outDir, `${name}-${other}.png`) });
  await page.keyboard.press('g');
  check((await viewer(page, 'renderer')) === renderer, `${name}: G switches back to ${renderer}`);

  check(requests.length === 0, `${name}: no network requests (${requests.join(', ')})`);
  check(errors.length === 0, `${name}: no console or page errors ${errors.join('; ')}`);
  await context.close();
}

// The flags of tests/viewer/browser_check.mjs: no GPU, so WebGL runs on SwiftShader.
const browser = await chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
         '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  for (const file of pages) await checkPage(browser, file);
} catch (e) {
  console.log(`FAIL ${e.stack || e}`);
  failures += 1;
} finally {
  await browser.close();
}
console.log(failures === 0 ? 'all strands viewer checks passed'
                           : `${failures} strands viewer checks failed`);
process.exit(failures === 0 ? 0 : 1);
