// Opens a page of `semsegmap view` from disk in headless Chromium with the network off, as a user
// would: waits for it to be ready, reads what it reports (window.semsegmapViewer and the DOM),
// clicks a localization on the canvas and one in the list, drags the frame slider with the
// keyboard, takes a screenshot and checks that the 3D canvas is not blank; optionally turns the
// view for a while and counts the frames drawn, and optionally picks another colouring in the
// page's switch first (what the map and its legend show then, and the canvas's pixels of each
// session's colour). Prints one line of JSON for tests/test_viewer_page.cpp.
// usage: node test_viewer_browser.mjs NODE_MODULES CHROMIUM PAGE.html SCREENSHOT.png [ROTATE_MS]
//        [COLOURING]
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [nodeModules, chromiumPath, pagePath, screenshot, rotateMs = '0', colouring = ''] = process.argv.slice(2);
const { chromium } = createRequire(path.join(path.resolve(nodeModules), 'noop.js'))('playwright-core');

// Root needs --no-sandbox; the rest keeps Chromium from reaching for the network at start and
// gives WebGL a software renderer on machines without a GPU.
const args = ['--no-sandbox', '--disable-background-networking', '--disable-component-update',
  '--disable-sync', '--no-first-run', '--disable-quic', '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'];

// The fraction of the canvas's pixels that are not its background, and how many colours it has.
function canvasContent() {
  const canvas = document.getElementById('view');
  const probe = document.createElement('canvas');
  probe.width = 320;
  probe.height = Math.round((320 * canvas.height) / canvas.width);
  const ctx = probe.getContext('2d');
  ctx.drawImage(canvas, 0, 0, probe.width, probe.height);
  const data = ctx.getImageData(0, 0, probe.width, probe.height).data;
  const [r0, g0, b0] = [data[0], data[1], data[2]];
  let other = 0;
  const colours = new Set();
  for (let i = 0; i < data.length; i += 4) {
    if (Math.abs(data[i] - r0) + Math.abs(data[i + 1] - g0) + Math.abs(data[i + 2] - b0) > 30) other++;
    colours.add((data[i] >> 4) * 256 + (data[i + 1] >> 4) * 16 + (data[i + 2] >> 4));
  }
  return { nonBackground: other / (data.length / 4), colours: colours.size };
}

// How many of the canvas's pixels are each of `colours` ([r, g, b]; a disc's shading darkens its
// rim, so within a few levels).
function pixelsOf(colours) {
  const canvas = document.getElementById('view');
  const probe = document.createElement('canvas');
  [probe.width, probe.height] = [canvas.width, canvas.height];
  const ctx = probe.getContext('2d');
  ctx.drawImage(canvas, 0, 0);
  const data = ctx.getImageData(0, 0, probe.width, probe.height).data;
  const counts = colours.map(() => 0);
  for (let i = 0; i < data.length; i += 4)
    colours.forEach((c, k) => {
      if (Math.abs(data[i] - c[0]) + Math.abs(data[i + 1] - c[1]) + Math.abs(data[i + 2] - c[2]) <= 24) counts[k]++;
    });
  return counts;
}

// Picks `mode` in the page's colouring switch, as a user does, and reports what the map is drawn
// in then, the sessions' legend and the canvas's pixels of each session's colour.
async function switchColouring(page, mode) {
  const before = await page.evaluate(() => window.semsegmapViewer.mapColours());
  await page.selectOption('#colouring', mode);
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const after = await page.evaluate(() => {
    const v = window.semsegmapViewer;
    const legend = [...document.querySelectorAll('#sessions li')].map((li) => ({
      session: Number(li.dataset.session), text: li.textContent.trim(),
      swatch: getComputedStyle(li.querySelector('.swatch')).backgroundColor }));
    return { selected: document.getElementById('colouring').value, mapColours: v.mapColours(),
             sessionColours: legend.map((l) => v.sessionColour(l.session)), legend,
             sessionLegendShown: !document.getElementById('session-legend').hidden,
             classLegendShown: !document.getElementById('class-legend').hidden,
             sessionTrajectories: v.sessionTrajectories() };
  });
  after.pixels = await page.evaluate(pixelsOf, after.sessionColours);
  return { mode, before, ...after };
}

// A localization with matches whose disc is on the canvas, not under a panel: its screen point.
function clickableLocalization() {
  const v = window.semsegmapViewer;
  const canvas = document.getElementById('view');
  const records = v.stats.localizations;
  const order = [...Array(records).keys()].sort((a, b) => Math.abs(a - records / 2) - Math.abs(b - records / 2));
  for (const i of order) {
    const p = v.screenPositionOfLocalization(i);
    if (p && document.elementFromPoint(p.x, p.y) === canvas && v.matchesOf(i) > 0) return { index: i, ...p };
  }
  return null;
}

async function run() {
  const started = Date.now();
  const browser = await chromium.launch({ executablePath: chromiumPath, args, timeout: 60000 });
  const context = await browser.newContext({ offline: true, viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const requests = [];
  const errors = [];
  page.on('request', (r) => requests.push(r.url()));
  page.on('pageerror', (e) => errors.push(e.message));
  const url = pathToFileURL(path.resolve(pagePath)).href;
  await page.goto(url);
  await page.waitForFunction(() => window.semsegmapViewer && (window.semsegmapViewer.ready || window.semsegmapViewer.error),
                             null, { timeout: 120000 });
  const out = { wallMs: Date.now() - started };
  Object.assign(out, await page.evaluate(() => {
    const v = window.semsegmapViewer;
    const stats = document.getElementById('stats');
    if (v.error) return { error: v.error };
    return { error: v.error, stats: v.stats, loadMs: v.loadMs, buildMs: v.buildMs, layers: v.layers(),
             unknownColour: v.classColour(0),
             dom: { segments: Number(stats.dataset.segments), localizations: Number(stats.dataset.localizations),
                    listed: document.querySelectorAll('#localizations li[data-index]').length,
                    legend: document.querySelectorAll('#legend li').length } };
  }));
  if (out.error) return finish(browser, out, requests, errors, url);
  if (out.stats.localizations > 0) await interact(page, out);
  if (colouring) out.colouring = await switchColouring(page, colouring);
  await page.screenshot({ path: screenshot });
  out.canvas = await page.evaluate(canvasContent);
  if (Number(rotateMs) > 0) out.rotation = await page.evaluate((ms) => window.semsegmapViewer.measureRotation(ms), Number(rotateMs));
  return finish(browser, out, requests, errors, url);
}

// A real mouse click on a localization's disc, then on another in the list, then the slider.
async function interact(page, out) {
  const target = await page.evaluate(clickableLocalization);
  out.click = { target };
  if (target) {
    await page.mouse.click(target.x, target.y);
    out.click.selected = await page.evaluate(() => window.semsegmapViewer.selected());
    out.click.domMatches = Number(await page.getAttribute('#selection', 'data-matches'));
    out.click.text = await page.textContent('#selection');
  }
  const other = out.stats.localizations - 1;
  await page.click(`#localizations li[data-index="${other}"]`);
  out.list = { index: other, selected: await page.evaluate(() => window.semsegmapViewer.selected()) };
  // Play runs through the frames; a second click pauses.
  const before = await page.textContent('#frame-label');
  await page.click('#play');
  await page.waitForFunction((label) => document.getElementById('frame-label').textContent !== label,
                             before, { timeout: 10000 });
  await page.click('#play');
  out.play = { before, after: await page.textContent('#frame-label') };
  await page.focus('#frame');
  await page.keyboard.press('End');
  out.slider = { label: await page.textContent('#frame-label'), selected: await page.evaluate(() => window.semsegmapViewer.selected()) };
  // The screenshot shows the clicked localization's matches, the mouse off the panels.
  if (target) await page.evaluate((i) => window.semsegmapViewer.select(i), target.index);
  await page.mouse.move(640, 790);
}

async function finish(browser, out, requests, errors, url) {
  await browser.close();
  out.foreignRequests = requests.filter((r) => r !== url && !r.startsWith('data:') && !r.startsWith('blob:'));
  out.pageErrors = errors;
  console.log(JSON.stringify(out));
}

run().catch((e) => {
  console.log(JSON.stringify({ failed: e.message }));
  process.exit(1);
});
