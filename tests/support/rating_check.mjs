// Drives a study's rating page (view/web/rate.html) in headless Chromium, as a subject would,
// and reports what the page showed as one JSON object on stdout. tests/test_study.cpp runs it.
//
//   node rating_check.mjs --url URL --script SCRIPT [--screenshot FILE.png]
//
// SCRIPT: one step per pair served, separated by ';'; each step's actions separated by ','.
// A step waits until the page serves a pair it has not served before, then does its
// actions, each waiting until the page shows the screen that follows it:
//   switch      click the switch button        key-switch  press S
//   choose:V    click grade V (+2, 0, -1 ...)  key-up, key-down  press ↑ / ↓
//   confirm     click Confirm                  key-enter   press Enter
//   next        click Next pair                key-next    press N
//   stop        click Stop twice               screenshot  take the screenshot now
//   await:F     nothing: wait until the page shows F (first, second) felt, as after a
//               switch made by the device's button
// After the last step it waits until the page serves nothing (every pair rated, or stopped).
// Result: {steps: [{title, screens: [screen after each action]}], final: screen, texts: [the
// page's visible text after each action], errors}. Exit 1 on a timeout, naming what was
// awaited; exit 0 with {"skipped": reason} when no Chromium can be started.
import { chromium } from '../../deploy/node/node_modules/playwright-core/index.mjs';
import { existsSync } from 'node:fs';

const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, a, i, all) => (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
const executable = process.env.CHROMIUM || ['/usr/bin/chromium', '/usr/bin/chromium-browser'].find((p) => existsSync(p));
if (!executable) {
  console.log(JSON.stringify({ skipped: 'no Chromium (install the Debian package chromium)' }));
  process.exit(0);
}

const browser = await chromium.launch({ executablePath: executable });
const result = { steps: [], texts: [], errors: [] };
let status = 0;
try {
  const page = await browser.newPage({ viewport: { width: 560, height: 900 } });
  page.on('pageerror', (e) => result.errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') result.errors.push(m.text()); });
  await page.goto(args.url, { timeout: 60000 });
  const snapshot = () => page.evaluate(() => (window.cohapticRating ? window.cohapticRating.snapshot() : null));
  const waitFor = async (what, test, seconds = 120) => {
    const until = Date.now() + seconds * 1000;
    for (;;) {
      const s = await snapshot();
      if (s && test(s)) return s;
      if (Date.now() > until) throw new Error(`timed out after ${seconds} s waiting for ${what}; last state: ${JSON.stringify(s)}`);
      await page.waitForTimeout(50);
    }
  };
  const act = {
    'switch': () => page.click('#switch'),
    'key-switch': () => page.keyboard.press('s'),
    'key-up': () => page.keyboard.press('ArrowUp'),
    'key-down': () => page.keyboard.press('ArrowDown'),
    'confirm': () => page.click('#confirm'),
    'key-enter': () => page.keyboard.press('Enter'),
    'next': () => page.click('#next'),
    'key-next': () => page.keyboard.press('n'),
    'stop': async () => { await page.click('#stop'); await page.click('#stop'); },
  };
  const served = new Set();
  for (const step of args.script.split(';')) {
    const s = await waitFor('a new pair served', (s) => s.screen && s.screen.serving && !served.has(s.screen.title));
    served.add(s.screen.title);
    const record = { title: s.screen.title, screens: [] };
    result.steps.push(record);
    for (const action of step.split(',').filter(Boolean)) {
      if (action === 'screenshot') {
        if (args.screenshot) await page.screenshot({ path: args.screenshot });
        continue;
      }
      if (action.startsWith('await:')) {
        const felt = action.slice(6);
        record.screens.push((await waitFor(`${felt} felt`, (s) => s.screen.feeling === felt)).screen);
        result.texts.push(await page.evaluate(() => document.body.innerText));
        continue;
      }
      const before = (await snapshot()).screens;
      if (action.startsWith('choose:')) await page.click(`.grade[data-value="${Number(action.slice(7))}"]`);
      else if (act[action]) await act[action]();
      else throw new Error(`unknown action '${action}'`);
      const after = await waitFor(`the screen after ${action}`, (s) => s.screens > before);
      record.screens.push(after.screen);
      result.texts.push(await page.evaluate(() => document.body.innerText));
    }
  }
  result.final = (await waitFor('the end of the session', (s) => s.screen && !s.screen.serving && !/starting/.test(s.screen.note))).screen;
  result.texts.push(await page.evaluate(() => document.body.innerText));
} catch (e) {
  result.error = e.message;
  status = 1;
}
await browser.close();
console.log(JSON.stringify(result));
process.exit(status);
