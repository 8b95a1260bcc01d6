// Opens cohaptic's live view in headless Chromium (driven by playwright-core) and reports,
// as one JSON object on stdout, what the page shows: its own state (window.cohapticView)
// and what a screenshot of it holds. tests/test_view.cpp runs it and judges the result.
//
//   node view_check.mjs --url URL --screenshot FILE.png [--seek SECONDS | --jump peak | --final 1]
//                       [--min-force N [--give-up SECONDS]] [--stay SECONDS] [--focus-tools 1] [--rigid-removed 1]
//                       [--width W --height H]
//
// Live: waits for frames with every tool present, takes the page's state, waits 1.5 s and
// takes it again at the next frame drawn (the strip chart must have moved on), freezes the drawing, takes a third
// state and a screenshot of that same picture. With --seek (a recording): asks the page to
// seek there and waits until the frame shown is the one at that time; with --jump peak, to
// jump to the largest force. Live with --min-force (instead of the two looks): the
// screenshot waits until every tool presses with at least N newtons, for 30 s (--give-up) at most: then
// it takes the screenshot anyway and exits 1, its "error" saying which condition failed and
// "unmet" the values it saw; --stay keeps the page open and drawing that long after the
// screenshot (make demo's watching browser); --focus-tools moves the camera close to the
// tools first (the page's T key); --rigid-removed colours the deformation without the rigid
// motion (the page's D key). With --final: waits until every user's status panel shows its
// final report (its client has finished).
// Pixels: the screenshot is decoded by the browser itself (an <img> drawn on a 2-D canvas)
// and counted: non-background pixels inside the projected box of the mesh, pixels of each
// user's colour on its tool's outline and along its force arrow, of the scale bar's line,
// and in each separating interface's box those of its separated faces, grooves and crack front.
// "screen": what the page shows, in CSS pixels: per user the arrow's length, its tip's
// distance from its tool's centre and the tool's radius on the screen; the legend's title,
// the arrow scale, the rigid-motion checkbox, the scale bar's text and length.
// Timings, in ms: "launchMs" Chromium's start; from then, "gotoMs" the page loaded,
// "connectedMs" and "firstFrameMs" first seen connected and drawing (a slow machine's).
// Exit status 0 with {"skipped": reason} when no Chromium can be started; 1 on a timeout,
// naming what was awaited (the screenshot is still taken, of whatever the page shows).
import { chromium } from '../../deploy/node/node_modules/playwright-core/index.mjs';
import { existsSync, readdirSync, readFileSync, writeFileSync } from 'node:fs';
import { getPriority } from 'node:os';

// playwright starts Chromium in a session of its own (setsid), and Linux shares the CPUs
// between sessions' autogroups before it looks at any process's nice value: `nice -n 19 node
// view_check.mjs` would leave Chromium an equal share beside the session it watches. So its
// autogroup is given this process's nice value (sched(7), "The autogroup feature").
function keepBrowserAtOurPriority() {
  const nice = getPriority();
  for (const entry of readdirSync('/proc')) {
    if (!/^\d+$/.test(entry)) continue;
    try {
      const stat = readFileSync(`/proc/${entry}/stat`, 'utf8');
      const parent = Number(stat.slice(stat.lastIndexOf(')') + 2).split(' ')[1]);
      if (parent === process.pid) writeFileSync(`/proc/${entry}/autogroup`, String(nice));
    } catch (e) {
      if (e.code !== 'ENOENT' && e.code !== 'ESRCH')
        console.error(`view_check: the browser's priority stays its own (${e.message})`);
    }
  }
}

const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, a, i, all) => (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
const width = Number(args.width || 1280), height = Number(args.height || 760);
const GIVE_UP_S = Number(args['give-up'] || 30);  // for the --min-force screenshot, from the browser's start
const executable = process.env.CHROMIUM || ['/usr/bin/chromium', '/usr/bin/chromium-browser'].find((p) => existsSync(p));
if (!executable) {
  console.log(JSON.stringify({ skipped: 'no Chromium (install the Debian package chromium)' }));
  process.exit(0);
}

const launching = Date.now();
// WebGL through SwiftShader (no graphics card here), and the page composited in software, as
// Chromium does on a machine without a usable card: compositing through SwiftShader as well
// costs about three times the CPU per frame drawn, and a browser below the session's priority
// then draws a frame every few seconds.
const browser = await chromium.launch({
  executablePath: executable,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--disable-gpu-compositing'],
});
keepBrowserAtOurPriority();
const started = Date.now();
const result = { errors: [] };
let page = null, pictured = false;
try {
  page = await browser.newPage({ viewport: { width, height } });
  page.on('pageerror', (e) => result.errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') result.errors.push(m.text()); });
  result.launchMs = started - launching;
  await page.goto(args.url, { timeout: GIVE_UP_S * 1000 });
  result.gotoMs = Date.now() - started;
  const snapshot = () => page.evaluate(() => window.cohapticView.snapshot());
  // The page's last state, and whether it passed `test` before `until` (a time in ms).
  const poll = async (test, until) => {
    for (;;) {
      const s = await page.evaluate(() => (window.cohapticView ? window.cohapticView.snapshot() : null));
      if (s && s.connected && result.connectedMs === undefined) result.connectedMs = Date.now() - started;
      if (s && s.framesDrawn > 0 && result.firstFrameMs === undefined) result.firstFrameMs = Date.now() - started;
      if (s && test(s)) return { s, met: true };
      if (Date.now() > until) return { s, met: false };
      await page.waitForTimeout(100);
    }
  };
  const waitFor = async (what, test, seconds = 60) => {
    const { s, met } = await poll(test, Date.now() + seconds * 1000);
    if (!met) throw new Error(`timed out after ${seconds} s waiting for ${what}; last state: ` +
      JSON.stringify(s && { connected: s.connected, frames: s.framesDrawn, frame: s.frame, users: s.users.map((u) => u.present) }));
    return s;
  };
  const everyToolPresent = (s) => s.framesDrawn >= 3 && s.users.length > 0 && s.users.every((u) => u.present);
  if (args.final !== undefined) {
    result.after = await waitFor('every user\'s final status report',
      (s) => s.users.length > 0 && s.users.every((u) => s.status[u.slot] && s.status[u.slot].final && u.panel.peak_force.includes('final')));
  } else if (args.jump !== undefined) {
    await waitFor('the recording\'s timeline', (s) => s.timeline && s.framesDrawn >= 1);
    await page.evaluate(() => window.cohapticView.command({ jump: 1 }));
    result.after = await waitFor('the frame of the largest force',
      (s) => s.timeline && s.timeline.time === s.timeline.peakForceTime && s.frame && s.frame.time === s.timeline.time);
  } else if (args['min-force'] !== undefined) {
    const least = Number(args['min-force']);
    const { s, met } = await poll((s) => everyToolPresent(s) && s.users.every((u) => u.pressing && u.forceMagnitude >= least),
      started + GIVE_UP_S * 1000);
    result.after = s;
    if (!met) {
      const users = s ? s.users.map((u) => ({ slot: u.slot, tool: u.tool, present: u.present, pressing: u.pressing, forceN: u.forceMagnitude })) : [];
      const failed = !s ? 'the page never started (no window.cohapticView)'
        : !s.connected ? 'the page is not connected to the view server'
        : s.framesDrawn < 3 ? `fewer than 3 frames drawn (${s.framesDrawn})`
        : !s.users.length ? 'the scene has no tools'
        : `not every tool present and pressing with at least ${least} N: ` +
          users.map((u) => `${u.tool} ${u.present ? (u.pressing ? 'pressing' : 'not pressing') : 'absent'} with ${u.forceN.toFixed(4)} N`).join(', ');
      result.error = `gave up after ${GIVE_UP_S} s: ${failed}`;
      result.unmet = { minForceN: least, connected: s ? s.connected : false, framesDrawn: s ? s.framesDrawn : 0, users };
    }
  } else if (args.seek === undefined) {
    result.before = await waitFor('frames with every tool present', (s) => everyToolPresent(s) && s.users.every((u) => u.chart));
    await page.waitForTimeout(1500);
    // A software renderer on a loaded machine may draw nothing for a while: the second look
    // is at the first frame drawn after those 1.5 s.
    const drawnBefore = (await snapshot()).framesDrawn;
    result.after = await waitFor('a frame drawn with every tool present, 1.5 s later',
      (s) => everyToolPresent(s) && s.framesDrawn > drawnBefore);
  } else {
    const target = Number(args.seek);
    await waitFor('the recording\'s timeline', (s) => s.timeline && s.framesDrawn >= 1);
    await page.evaluate((t) => window.cohapticView.command({ seek: t }), target);
    result.after = await waitFor(`the frame at ${target} s`,
      (s) => s.timeline && Math.abs(s.timeline.time - target) < 1e-6 && s.frame && s.frame.time <= target + 1e-6 &&
        target - s.frame.time < 1.5 / s.scene.frameRateHz && s.users.every((u) => u.chart));
  }
  // The screenshot is taken even when its condition was not met (the page may not have started).
  const ready = await page.evaluate(() => !!window.cohapticView);
  if (ready) {
    if (args['focus-tools'] !== undefined) await page.keyboard.press('t');
    if (args['rigid-removed'] !== undefined) await page.keyboard.press('d');
    await page.evaluate(() => window.cohapticView.freeze(true));
    // The frame being drawn lands, and the page renders what the keys changed: two animation
    // frames later its draw has run since (a software renderer on a loaded machine may take
    // longer than the wait to get one).
    await page.waitForTimeout(300);
    await page.evaluate(() => new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done))));
    result.shown = await snapshot();
    result.screen = await screen(page, result.shown);
  }
  const png = await page.screenshot({ path: args.screenshot });
  pictured = true;
  if (ready) result.pixels = await page.evaluate(async ({ data, shown, screen }) => {
    const image = new Image();
    image.src = `data:image/png;base64,${data}`;
    await image.decode();
    const canvas = document.createElement('canvas');
    canvas.width = image.width;
    canvas.height = image.height;
    const ctx = canvas.getContext('2d');
    ctx.drawImage(image, 0, 0);
    const pixels = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    const scale = image.width / window.innerWidth;
    const at = (x, y) => {
      const i = 4 * (Math.round(y * scale) * canvas.width + Math.round(x * scale));
      return [pixels[i], pixels[i + 1], pixels[i + 2]];
    };
    const distance = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    const background = [0x15, 0x17, 0x1c];
    const clip = (b) => ({ x0: Math.max(b.x0, shown.canvas.x), y0: Math.max(b.y0, shown.canvas.y),
      x1: Math.min(b.x1, shown.canvas.x + shown.canvas.width - 1), y1: Math.min(b.y1, shown.canvas.y + shown.canvas.height - 1) });
    const count = (box, test, step = 2) => {
      let n = 0, all = 0;
      for (let y = Math.ceil(box.y0); y <= box.y1; y += step)
        for (let x = Math.ceil(box.x0); x <= box.x1; x += step) { ++all; if (test(at(x, y))) ++n; }
      return { matching: n, sampled: all };
    };
    const hex = (c) => [1, 3, 5].map((k) => parseInt(c.slice(k, k + 2), 16));
    const mesh = count(clip(shown.meshScreenBox), (p) => distance(p, background) > 30);
    const outside = count({ x0: shown.canvas.x, y0: shown.canvas.y, x1: shown.canvas.x + 40, y1: shown.canvas.y + 40 },
      (p) => distance(p, background) > 30);
    const users = shown.users.map((u) => {
      const colour = hex(u.colour);
      const near = (p) => distance(p, colour) < 60;
      const nearby = (x, y) => {
        for (let dy = -2; dy <= 2; ++dy) for (let dx = -2; dx <= 2; ++dx) if (near(at(x + dx, y + dy))) return true;
        return false;
      };
      // The tool's outline, a ring at its radius on the screen.
      let tool = null;
      if (u.toolScreen) {
        let on = 0, sampled = 0;
        for (let k = 0; k < 48; ++k) {
          const x = u.toolScreen.x0 + 0.97 * u.toolScreenRadius * Math.cos(k * Math.PI / 24), y = u.toolScreen.y0 + 0.97 * u.toolScreenRadius * Math.sin(k * Math.PI / 24);
          if (x < shown.canvas.x || y < shown.canvas.y || x >= shown.canvas.x + shown.canvas.width || y >= shown.canvas.y + shown.canvas.height) continue;
          ++sampled;
          if (nearby(x, y)) ++on;
        }
        tool = { matching: on, sampled };
      }
      let arrow = null;
      if (u.arrowTipScreen) {
        // Along the arrow, from its origin on the tool's surface to its tip.
        const a = u.arrowOriginScreen, b = u.arrowTipScreen;
        let on = 0, sampled = 0;
        for (let f = 0.1; f <= 0.95; f += 0.05) {
          const x = a.x0 + f * (b.x0 - a.x0), y = a.y0 + f * (b.y0 - a.y0);
          ++sampled;
          if (nearby(x, y)) ++on;
        }
        arrow = { matching: on, sampled };
      }
      return { slot: u.slot, tool, arrow };
    });
    // The scale bar's line: its lowest row, its bottom border.
    const bar = screen.scaleBar.box;
    const row = Math.floor(bar.y + bar.height) - 1;
    const scaleBar = count({ x0: bar.x + 1, y0: row, x1: bar.x + bar.width - 2, y1: row },
      (p) => distance(p, [0xe6, 0xe6, 0xe6]) < 40);
    // A separating interface's overlay, every pixel of its box: separated faces (drawn fully
    // separated in exactly this colour), grooves and the crack front (thin lines).
    const interfaces = (shown.interfaceScreenBoxes || []).map((box) => {
      const within = (colour, most) => (p) => distance(p, hex(colour)) < most;
      return {
        separated: count(clip(box), within('#ff8a65', 12), 1),
        groove: count(clip(box), within('#ffffff', 12), 1),
        front: count(clip(box), within('#00e5ff', 40), 1),
      };
    });
    return { mesh, corner: outside, users, scaleBar, interfaces };
  }, { data: png.toString('base64'), shown: result.shown, screen: result.screen });
  if (args.stay !== undefined && !result.error) {
    // Watching on, drawing every frame, for as long as asked (the demo's browser).
    await page.evaluate(() => window.cohapticView.freeze(false));
    await page.waitForTimeout(Number(args.stay) * 1000);
    result.stayed = await snapshot();
  }
} catch (e) {
  result.error = e.message;
  // The picture as it is, to see why.
  if (page && !pictured) await page.screenshot({ path: args.screenshot }).catch(() => {});
}
await browser.close();
console.log(JSON.stringify(result));
process.exit(result.error ? 1 : 0);

// What the page shows, in CSS pixels (see the header).
async function screen(page, shown) {
  const dom = await page.evaluate(() => {
    const text = (id) => document.getElementById(id).textContent;
    const line = document.getElementById('scale-bar-line').getBoundingClientRect();
    return {
      legendTitle: text('legend-title'), arrowScale: text('arrow-scale'), rigidMotionRemoved: document.getElementById('rigid-removed').checked,
      scaleBar: { text: text('scale-bar-text'), pixels: line.width, box: { x: line.left, y: line.top, width: line.width, height: line.height } },
    };
  });
  const apart = (a, b) => Math.hypot(a.x0 - b.x0, a.y0 - b.y0);
  const users = shown.users.map((u) => (u.toolScreen && u.arrowTipScreen ? {
    slot: u.slot, arrowPixels: apart(u.arrowOriginScreen, u.arrowTipScreen), tipFromToolPixels: apart(u.toolScreen, u.arrowTipScreen),
    toolRadiusPixels: u.toolScreenRadius, tipOutsideTool: apart(u.toolScreen, u.arrowTipScreen) > u.toolScreenRadius,
  } : { slot: u.slot, arrowPixels: 0 }));
  return { ...dom, users };
}
