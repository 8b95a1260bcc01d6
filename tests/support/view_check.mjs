// Opens cohaptic's live view in headless Chromium (driven by playwright-core) and reports,
// as one JSON object on stdout, what the page shows: its own state (window.cohapticView)
// and what a screenshot of it holds. tests/test_view.cpp runs it and judges the result.
//
//   node view_check.mjs --url URL --screenshot FILE.png [--seek SECONDS | --jump peak | --final 1]
//                       [--min-force N] [--stay SECONDS] [--focus-tools 1] [--width W --height H]
//
// Live: waits for frames with every tool present, takes the page's state, waits 1.5 s and
// takes it again at the next frame drawn (the strip chart must have moved on), freezes the drawing, takes a third
// state and a screenshot of that same picture. With --seek (a recording): asks the page to
// seek there and waits until the frame shown is the one at that time; with --jump peak, to
// jump to the largest force. Live with --min-force (instead of the two looks): the
// screenshot waits until every tool presses with at least N newtons; --stay keeps the page open and drawing that long after
// the screenshot (make demo's watching browser); --focus-tools moves the camera close to
// the tools first (the page's T key). With --final: waits until every user's status panel shows its
// final report (its client has finished).
// Pixels: the screenshot is decoded by the browser itself (an <img> drawn on a 2-D canvas)
// and counted: non-background pixels inside the projected box of the mesh, pixels of each
// user's colour around its tool and along its force arrow.
// Exit status 0 with {"skipped": reason} when no Chromium can be started; 1 on a timeout,
// naming what was awaited.
import { chromium } from '../../deploy/node/node_modules/playwright-core/index.mjs';
import { existsSync, writeFileSync } from 'node:fs';

const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, a, i, all) => (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
const width = Number(args.width || 1280), height = Number(args.height || 760);
const executable = process.env.CHROMIUM || ['/usr/bin/chromium', '/usr/bin/chromium-browser'].find((p) => existsSync(p));
if (!executable) {
  console.log(JSON.stringify({ skipped: 'no Chromium (install the Debian package chromium)' }));
  process.exit(0);
}

const browser = await chromium.launch({
  executablePath: executable,
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const result = { errors: [] };
try {
  const page = await browser.newPage({ viewport: { width, height } });
  page.on('pageerror', (e) => result.errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') result.errors.push(m.text()); });
  await page.goto(args.url);
  const snapshot = () => page.evaluate(() => window.cohapticView.snapshot());
  const waitFor = async (what, test, seconds = 60) => {
    const until = Date.now() + seconds * 1000;
    for (;;) {
      const s = await page.evaluate(() => (window.cohapticView ? window.cohapticView.snapshot() : null));
      if (s && test(s)) return s;
      if (Date.now() > until) throw new Error(`timed out after ${seconds} s waiting for ${what}; last state: ` +
        JSON.stringify(s && { connected: s.connected, frames: s.framesDrawn, frame: s.frame, users: s.users.map((u) => u.present) }));
      await page.waitForTimeout(100);
    }
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
    result.after = await waitFor(`every tool pressing with at least ${args['min-force']} N`,
      (s) => everyToolPresent(s) && s.users.every((u) => u.pressing && u.forceMagnitude >= Number(args['min-force'])), 120);
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
  if (args['focus-tools'] !== undefined) await page.keyboard.press('t');
  await page.evaluate(() => window.cohapticView.freeze(true));
  await page.waitForTimeout(300);  // the frame being drawn lands
  result.shown = await snapshot();
  const png = await page.screenshot({ path: args.screenshot });
  result.pixels = await page.evaluate(async ({ data, shown }) => {
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
    const count = (box, test) => {
      let n = 0, all = 0;
      for (let y = Math.ceil(box.y0); y <= box.y1; y += 2)
        for (let x = Math.ceil(box.x0); x <= box.x1; x += 2) { ++all; if (test(at(x, y))) ++n; }
      return { matching: n, sampled: all };
    };
    const hex = (c) => [1, 3, 5].map((k) => parseInt(c.slice(k, k + 2), 16));
    const mesh = count(clip(shown.meshScreenBox), (p) => distance(p, background) > 30);
    const outside = count({ x0: shown.canvas.x, y0: shown.canvas.y, x1: shown.canvas.x + 40, y1: shown.canvas.y + 40 },
      (p) => distance(p, background) > 30);
    const users = shown.users.map((u) => {
      const colour = hex(u.colour);
      const near = (p) => distance(p, colour) < 60;
      const tool = u.toolScreen ? count(clip({ x0: u.toolScreen.x0 - 12, y0: u.toolScreen.y0 - 12, x1: u.toolScreen.x0 + 12, y1: u.toolScreen.y0 + 12 }), near) : null;
      let arrow = null;
      if (u.arrowTipScreen && u.toolScreen) {
        // Along the arrow, from a third of the way (past the tool's sphere) to the tip.
        let on = 0, sampled = 0;
        for (let f = 0.35; f <= 0.95; f += 0.05) {
          const x = u.toolScreen.x0 + f * (u.arrowTipScreen.x0 - u.toolScreen.x0), y = u.toolScreen.y0 + f * (u.arrowTipScreen.y0 - u.toolScreen.y0);
          ++sampled;
          let hit = false;
          for (let dy = -2; dy <= 2 && !hit; ++dy) for (let dx = -2; dx <= 2 && !hit; ++dx) hit = near(at(x + dx, y + dy));
          if (hit) ++on;
        }
        arrow = { matching: on, sampled };
      }
      return { slot: u.slot, tool, arrow };
    });
    return { mesh, corner: outside, users };
  }, { data: png.toString('base64'), shown: result.shown });
  if (args.stay !== undefined) {
    // Watching on, drawing every frame, for as long as asked (the demo's browser).
    await page.evaluate(() => window.cohapticView.freeze(false));
    await page.waitForTimeout(Number(args.stay) * 1000);
    result.stayed = await snapshot();
  }
} catch (e) {
  result.error = e.message;
}
await browser.close();
console.log(JSON.stringify(result));
process.exit(result.error ? 1 : 0);
