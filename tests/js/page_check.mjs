// The live view's page in a real browser: headless Chromium (Debian's `chromium`) through
// puppeteer-core loads the page from a LiveServer (`swarmbox view`, or a test's server), waits for
// the drones, moves the time slider with the mouse and checks the drones moved, selects a drone
// (its camera thumbnail at 75 % and at the end), clicks an event (the time jumps to it) and saves a screenshot.
//
//   node page_check.mjs URL --drones N [--screenshot FILE] [--chromium PATH] [--timeout-ms MS]
//
// Prints one JSON object on stdout: {"ok": bool, "problems": [...], "before": state, "after": state,
// ...} (state: window.swarmboxView.state() of the page). Exit 0 when every check passed, 1 when
// one failed, 2 on bad usage or when the browser cannot start.
import puppeteer from "puppeteer-core";

const args = process.argv.slice(2);
const url = args.shift();
let drones = 1, screenshot = "", chromium = "/usr/bin/chromium", timeoutMs = 60000;
while (args.length > 0) {
  const a = args.shift();
  if (a === "--drones") drones = Number(args.shift());
  else if (a === "--screenshot") screenshot = args.shift();
  else if (a === "--chromium") chromium = args.shift();
  else if (a === "--timeout-ms") timeoutMs = Number(args.shift());
  else { console.error(`page_check: unknown argument ${a}`); process.exit(2); }
}
if (!url) {
  console.error("usage: node page_check.mjs URL --drones N [--screenshot FILE] [--chromium PATH] [--timeout-ms MS]");
  process.exit(2);
}

const result = { ok: false, problems: [], pageErrors: [], requests: [] };
const problem = (text) => result.problems.push(text);
let browser;
try {
  browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    // --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start.
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--hide-scrollbars"],
    defaultViewport: { width: 1280, height: 760 },
  });
} catch (e) {
  console.error(`page_check: cannot start ${chromium}: ${e.message}`);
  process.exit(2);
}
const timer = setTimeout(() => {
  problem(`timeout after ${timeoutMs} ms`);
  done();
}, timeoutMs);

async function done() {
  clearTimeout(timer);
  result.ok = result.problems.length === 0;
  process.stdout.write(JSON.stringify(result) + "\n");
  await browser.close().catch(() => {});
  process.exit(result.ok ? 0 : 1);
}

try {
  const page = await browser.newPage();
  const origin = new URL(url).origin;
  page.on("pageerror", (e) => result.pageErrors.push(String(e.message ?? e)));
  page.on("request", (r) => {
    // The page is self-contained: nothing may leave the server it came from.
    const u = r.url();
    if (!u.startsWith(origin) && !u.startsWith("data:")) result.requests.push(u);
  });
  await page.goto(url, { waitUntil: "load" });
  const state = () => page.evaluate(() => window.swarmboxView.state());

  // The drones appear, and the history has stopped arriving.
  await page.waitForFunction((n) => Object.keys(window.swarmboxView.state().drones).length >= n,
    { timeout: timeoutMs / 2, polling: 100 }, drones);
  let last = -1;
  for (;;) {
    const s = await state();
    if (s.messages === last) break;
    last = s.messages;
    await new Promise((r) => setTimeout(r, 500));
  }
  result.before = await state();
  if (Object.keys(result.before.drones).length < drones) problem(`only ${Object.keys(result.before.drones).length} drones drawn`);

  // Move the slider with the mouse: to 25 % of its track, then to 75 %.
  const slider = await page.$("#slider");
  const box = await slider.boundingBox();
  const clickAt = async (f) => {
    await page.mouse.click(box.x + 8 + (box.width - 16) * f, box.y + box.height / 2);
    await new Promise((r) => setTimeout(r, 300));
    return state();
  };
  result.quarter = await clickAt(0.25);
  result.after = await clickAt(0.75);
  const span = result.after.t1 - result.after.t0;
  if (!(result.after.t > result.quarter.t + 0.3 * span)) {
    problem(`the slider did not move the time: t=${result.quarter.t} then t=${result.after.t}`);
  }
  let moved = 0;
  for (const [name, d] of Object.entries(result.after.drones)) {
    const q = result.quarter.drones[name];
    if (q && Math.hypot(d.px[0] - q.px[0], d.px[1] - q.px[1]) > 5) moved++;
  }
  result.moved = moved;
  if (moved === 0) problem("no drone moved on the screen when the slider moved");

  // Select the first drone in the list: its camera frame shows.
  await page.click("#drones .drone");
  await new Promise((r) => setTimeout(r, 300));
  result.selected = await state();
  result.cameraShown = result.selected.camera;  // at 75 % of the time range
  result.cameraAtEnd = (await clickAt(1.0)).camera;

  // An event jumps to its time.
  const events = await page.$$("#events .ev");
  if (events.length > 0) {
    const target = events[Math.floor(events.length / 2)];
    const eventT = Number(await target.$eval(".t", (e) => e.textContent));
    await target.click();
    await new Promise((r) => setTimeout(r, 300));
    const s = await state();
    result.eventJump = { eventT, t: s.t };
    if (Math.abs(s.t - eventT) > 0.06) problem(`clicking the event at ${eventT} s set t=${s.t}`);
  } else {
    result.eventJump = null;
  }
  // Back to the 75 % point for the picture, the selected drone's camera in the corner.
  result.after = await clickAt(0.75);
  if (screenshot) await page.screenshot({ path: screenshot });
  if (result.pageErrors.length) problem(`page errors: ${result.pageErrors.join("; ")}`);
  if (result.requests.length) problem(`the page fetched from elsewhere: ${result.requests.join(", ")}`);
} catch (e) {
  problem(`${e.message}`);
}
await done();
