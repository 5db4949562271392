// Drives viewer pages written by flexkin::WriteViewerHtml in headless Chromium (the system's
// Debian package, through playwright-core from tools/node) and checks that they work offline and
// respond to every control. Run by tests/viewer_test.cc:
//   node tests/viewer/browser_check.mjs TOOLS_NODE_DIR OUT_DIR PAGE.html...
// Writes screenshots to OUT_DIR, prints one line per check and a summary line per page
// ("fps ..."), and exits with 1 if any check failed. Environment: FLEXKIN_CHROMIUM overrides
// the browser (default /usr/bin/chromium); FLEXKIN_MIN_FPS the frame-rate floor (default 20).
import { createRequire } from 'node:module';
import { existsSync } from 'node:fs';
import { basename, join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [toolsDir, outDir, ...pages] = process.argv.slice(2);
if (!toolsDir || !outDir || pages.length === 0) {
  console.error('usage: node browser_check.mjs TOOLS_NODE_DIR OUT_DIR PAGE.html...');
  process.exit(2);
}
const chromiumPath = process.env.FLEXKIN_CHROMIUM || '/usr/bin/chromium';
// The page must keep drawing while it plays. This floor is far below what any machine draws (59
// fps here); the frame rate itself is a measurement (bench/viewer_fps.sh), not a test's pass mark.
const minFps = Number(process.env.FLEXKIN_MIN_FPS || 5);
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

// A hash of the canvas's pixels and how much of it is not background.
async function picture(page) {
  return page.evaluate(() => {
    const c = document.getElementById('view');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let hash = 2166136261, drawn = 0;
    const colors = new Set();
    for (let i = 0; i < d.length; i += 4) {
      const v = (d[i] << 16) | (d[i + 1] << 8) | d[i + 2];
      hash = Math.imul(hash ^ v, 16777619) >>> 0;
      if (v !== 0xfbfbfd) drawn += 1;
      if (colors.size < 64) colors.add(v);
    }
    return { hash, drawnFraction: drawn / (d.length / 4), colors: colors.size };
  });
}

// The strokes the page makes while it draws a frame (one step on and back), each with its path
// (the points of its moveTo and lineTo calls), width and cap; the points of the frame on screen,
// the view's scale, the links drawn and the result's link radii.
async function recordFrameStrokes(page) {
  await page.evaluate(() => {
    const proto = CanvasRenderingContext2D.prototype;
    const log = { strokes: [], path: [], saved: {} };
    window.capsuleLog = log;
    for (const method of ['beginPath', 'moveTo', 'lineTo', 'stroke']) {
      log.saved[method] = proto[method];
    }
    proto.beginPath = function () { log.path = []; return log.saved.beginPath.call(this); };
    proto.moveTo = function (x, y) {
      log.path.push([x, y]);
      return log.saved.moveTo.call(this, x, y);
    };
    proto.lineTo = function (x, y) {
      log.path.push([x, y]);
      return log.saved.lineTo.call(this, x, y);
    };
    proto.stroke = function (...args) {
      if (this.canvas.id === 'view') {
        log.strokes.push({ path: log.path.slice(), width: this.lineWidth, cap: this.lineCap });
      }
      return log.saved.stroke.apply(this, args);
    };
  });
  // Draw a frame (one step on and back) with the recorder on, then put the methods back.
  await page.locator('#view').focus();
  await page.keyboard.press('ArrowRight');
  await sleep(100);
  await page.evaluate(() => { window.capsuleLog.strokes = []; });
  await page.keyboard.press('ArrowLeft');
  await sleep(100);
  const got = await page.evaluate(() => {
    const log = window.capsuleLog;
    const proto = CanvasRenderingContext2D.prototype;
    for (const method of Object.keys(log.saved)) proto[method] = log.saved[method];
    const v = window.flexkinViewer;
    const data = JSON.parse(document.getElementById('flexkin-data').textContent);
    const points = [];
    for (let i = 0; i < v.numPoints; ++i) points.push(v.pointOnScreen(i));
    return { strokes: log.strokes, points, scale: v.view.scale, radii: data.link_radii,
             links: v.links };
  });
  return got;
}

// A page whose result has link radii draws each link of the current frame as its capsule: a
// round-capped stroke from point to point, 2 x radius wide in CSS pixels (view.scale CSS pixels
// per length unit; in perspective the depth factor of the link's midpoint, between 0.75 and 1.5,
// scales it). The strokes are recorded while the page draws a frame, and each link's must be
// there. `perspective`: only the factor's range is checked.
async function checkCapsules(page, name, perspective) {
  const got = await recordFrameStrokes(page);
  let worst = 0, missing = 0, drawn = 0;
  const near = (p, q) => Math.hypot(p[0] - q.x, p[1] - q.y) < 1e-6;
  for (let i = 0; i + 1 < got.points.length; ++i) {
    const r = got.radii[i];
    if (!(r > 0)) continue;
    const want = 2 * r * got.scale;
    const strokes = got.strokes.filter((s) => s.cap === 'round' && s.path.length === 2 &&
        near(s.path[0], got.points[i]) && near(s.path[1], got.points[i + 1]) &&
        s.width > 0.7 * want && s.width < 1.6 * want);
    if (strokes.length !== 1) {
      missing += 1;
      continue;
    }
    drawn += 1;
    const ratio = strokes[0].width / want;
    if (perspective) {
      if (!(ratio >= 0.75 - 1e-6 && ratio <= 1.5 + 1e-6)) worst = Math.max(worst, Infinity);
    } else {
      worst = Math.max(worst, Math.abs(ratio - 1));
    }
  }
  // The canvas keeps lineWidth as a float32.
  check(missing === 0 && drawn > 0 && worst <= 1e-6,
        `${name}: ${drawn} links drawn as capsules, stroke 2 x radius x scale ` +
        `${perspective ? '(perspective: x 0.75 to 1.5) ' : ''}(largest relative difference ` +
        `${worst.toExponential(1)}, ${missing} missing)`);
}

// A tree's page draws every link of the current frame from its parent's point to its child's: for
// each of the page's links [a, b] (checked against the tree's parents), some stroke's path has a
// moveTo at point a's pixel followed by a lineTo at point b's.
async function checkTreeLinks(page, name, parents) {
  const got = await recordFrameStrokes(page);
  const near = (p, q) => Math.hypot(p[0] - q.x, p[1] - q.y) < 1e-6;
  let missing = 0, wrong = 0;
  const want = new Set();
  parents.forEach((p, c) => { if (p >= 0) want.add(`${p}-${c}`); });
  for (const [a, b] of got.links) if (!want.delete(`${a}-${b}`)) wrong += 1;
  for (const [a, b] of got.links) {
    const found = got.strokes.some((s) => s.path.some((q, k) => k + 1 < s.path.length &&
        near(q, got.points[a]) && near(s.path[k + 1], got.points[b])));
    if (!found) missing += 1;
  }
  check(missing === 0 && wrong === 0 && want.size === 0 && got.links.length > 0,
        `${name}: the tree's ${got.links.length} links drawn parent to child (${missing} ` +
        `missing, ${wrong + want.size} not the tree's)`);
}

const frame = (page) => page.evaluate(() => window.flexkinViewer.frame);
const playing = (page) => page.evaluate(() => window.flexkinViewer.playing);

async function checkPage(browser, file) {
  const name = basename(file, '.html');
  const url = pathToFileURL(resolve(file)).href;
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  // Offline: every request but the page itself is refused, and counted.
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

  await page.goto(url);
  await page.waitForFunction(() => window.flexkinViewer && window.flexkinViewer.stats.draws > 0);
  const info = await page.evaluate(() => {
    const v = window.flexkinViewer;
    const data = JSON.parse(document.getElementById('flexkin-data').textContent);
    return { dim: v.dim, numFrames: v.numFrames, numPoints: v.numPoints, steps: data.steps,
             linkRadii: Boolean(data.link_radii), tree: data.tree || null };
  });
  // The point drawn as the leading end's red dot: a tree's first driven point.
  const leadPoint = info.tree ? info.tree.targets[0] : 0;
  const n = info.numFrames;
  console.log(`--- ${name}: ${info.dim}D, ${info.numPoints - 1} links, ${n} frames`);
  check(await playing(page), `${name}: plays on opening (autoplay)`);
  await page.screenshot({ path: join(outDir, `${name}-opened.png`) });

  // Pause with the space bar; the picture must then stay still.
  await page.locator('#view').focus();
  await page.keyboard.press('Space');
  check(!(await playing(page)), `${name}: space pauses`);
  const still1 = await picture(page);
  await sleep(400);
  const still2 = await picture(page);
  check(still1.hash === still2.hash, `${name}: paused picture stays still`);
  // Not blank: something drawn, and the leading end's red dot where the chain's first point is.
  const lead = await page.evaluate((i) => {
    const v = window.flexkinViewer;
    const c = document.getElementById('view');
    const at = v.pointOnScreen(i);
    const r = c.width / c.getBoundingClientRect().width;
    return Array.from(c.getContext('2d').getImageData(Math.round(at.x * r),
                                                      Math.round(at.y * r), 1, 1).data);
  }, leadPoint);
  if (info.tree) await checkTreeLinks(page, name, info.tree.parents);
  if (info.linkRadii) {
    await checkCapsules(page, name, false);
    if (info.dim === 3) {
      await page.click('#perspective');
      await sleep(50);
      await checkCapsules(page, `${name} in perspective`, true);
      await page.click('#perspective');
      await sleep(50);
    }
  }
  check(still1.drawnFraction > 0.002 && still1.colors > 4 && lead[0] > 180 && lead[1] < 90,
        `${name}: canvas not blank (${(100 * still1.drawnFraction).toFixed(1)}% drawn, ` +
        `${still1.colors} colours, leading end rgb(${lead.slice(0, 3)}))`);

  // Play with the button: the picture and the frame must change.
  await page.click('#play');
  const f0 = await frame(page);
  const moving1 = await picture(page);
  await sleep(500);
  const moving2 = await picture(page);
  const f1 = await frame(page);
  check(moving1.hash !== moving2.hash && f1 !== f0,
        `${name}: picture changes while playing (frame ${f0} -> ${f1})`);
  await page.screenshot({ path: join(outDir, `${name}-playing.png`) });
  await page.click('#play');
  check(!(await playing(page)) && (await page.textContent('#play')) === 'Play',
        `${name}: play button pauses`);

  // Scrub: set the timeline, then click on it; the counter says where we are.
  const k = Math.floor(0.37 * (n - 1));
  await page.evaluate((value) => {
    const t = document.getElementById('timeline');
    t.value = String(value);
    t.dispatchEvent(new Event('input', { bubbles: true }));
  }, k);
  await sleep(50);
  const counter = await page.textContent('#counter');
  check(counter.includes(`frame ${k + 1} / ${n}`) &&
        (info.tree !== null || counter.includes(`step ${info.steps[k]} /`)),
        `${name}: scrubbed to frame ${k + 1}, counter says "${counter}"`);
  const box = await page.locator('#timeline').boundingBox();
  await page.mouse.click(box.x + 0.75 * box.width, box.y + box.height / 2);
  const clicked = await frame(page);
  check(Math.abs(clicked - 0.75 * (n - 1)) <= 0.05 * n + 1,
        `${name}: clicking the timeline at 75% goes to frame ${clicked} of ${n}`);
  await page.locator('#view').focus();
  await page.keyboard.press('ArrowRight');
  check((await frame(page)) === Math.min(n - 1, clicked + 1), `${name}: right arrow steps on`);
  await page.keyboard.press('ArrowLeft');
  check((await frame(page)) === clicked, `${name}: left arrow steps back`);

  // Leader path and trails change the picture.
  await sleep(50);
  const before = await picture(page);
  await page.click('#leader');
  await sleep(50);
  const noLeader = await picture(page);
  check(noLeader.hash !== before.hash, `${name}: leader-path toggle changes the picture`);
  await page.click('#leader');
  await page.fill('#trail-points', `0, ${info.numPoints - 1}`);
  await page.press('#trail-points', 'Enter');
  if (!(await page.isChecked('#trails'))) await page.click('#trails');
  await sleep(50);
  const withTrails = await picture(page);
  check(withTrails.hash !== before.hash, `${name}: trails change the picture`);
  // Clicking a point toggles its trail.
  const middle = Math.floor((info.numPoints - 1) / 2);
  const at = await page.evaluate((i) => window.flexkinViewer.pointOnScreen(i), middle);
  const canvasBox = await page.locator('#view').boundingBox();
  await page.mouse.click(canvasBox.x + at.x, canvasBox.y + at.y);
  await sleep(50);
  const legend = await page.textContent('#legend');
  check(legend.includes(`point ${middle}`), `${name}: clicking point ${middle} adds its trail ` +
        `("${legend}")`);
  await page.screenshot({ path: join(outDir, `${name}-trails.png`) });

  // Moving the view changes the picture; Reset view gives the first picture back.
  const home = await picture(page);
  const cx = canvasBox.x + canvasBox.width / 2, cy = canvasBox.y + canvasBox.height / 2;
  await page.mouse.move(cx, cy);
  await page.mouse.down();
  await page.mouse.move(cx + 90, cy + 40, { steps: 5 });
  await page.mouse.up();
  await sleep(50);
  const dragged = await picture(page);
  check(dragged.hash !== home.hash, `${name}: dragging ${info.dim === 2 ? 'pans' : 'orbits'}`);
  await page.screenshot({ path: join(outDir, `${name}-dragged.png`) });
  await page.mouse.wheel(0, -300);
  await sleep(50);
  const zoomed = await picture(page);
  check(zoomed.hash !== dragged.hash, `${name}: the wheel zooms`);
  if (info.dim === 3) {
    await page.click('#perspective');
    await sleep(50);
    check((await picture(page)).hash !== zoomed.hash, `${name}: perspective toggle`);
    await page.click('#perspective');
  }
  await page.click('#reset');
  await sleep(50);
  check((await picture(page)).hash === home.hash, `${name}: reset view restores the picture`);

  // Frame rate while playing at 8x from the first frame: fast enough that every display frame
  // shows a new frame of the motion, so every one is drawn.
  await page.selectOption('#speed', '8');
  await page.keyboard.press('Home');
  await page.evaluate(() => {
    Object.assign(window.flexkinViewer.stats, { ticks: 0, draws: 0, drawMs: 0, maxDrawMs: 0 });
  });
  const t0 = Date.now();
  await page.click('#play');
  await sleep(3000);
  const perf = await page.evaluate(() => ({ ...window.flexkinViewer.stats,
                                            frame: window.flexkinViewer.frame }));
  const seconds = (Date.now() - t0) / 1000;
  const fps = perf.draws / seconds;
  console.log(`${name}: fps ${fps.toFixed(1)} while playing at 8x (${perf.draws} frames drawn ` +
              `in ${seconds.toFixed(2)} s, ${(perf.ticks / seconds).toFixed(1)} animation ` +
              `callbacks/s, mean draw ${(perf.drawMs / perf.draws).toFixed(2)} ms, max ` +
              `${perf.maxDrawMs.toFixed(2)} ms)`);
  check(fps >= minFps, `${name}: keeps drawing while playing (${fps.toFixed(1)} >= ${minFps} fps)`);

  check(requests.length === 0, `${name}: no network requests (${requests.join(', ')})`);
  check(errors.length === 0, `${name}: no console or page errors ${errors.join('; ')}`);
  await context.close();
}

// launch() gives the browser a fresh, temporary user-data-dir of its own and removes it on close.
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
console.log(failures === 0 ? 'all viewer checks passed' : `${failures} viewer checks failed`);
process.exit(failures === 0 ? 0 : 1);
