// node shot.mjs URL WAIT_S OUT.png:WIDTHxHEIGHT [OUT2.png:WxH ...]
// Opens URL in headless Debian chromium (no sandbox, no GPU, no background traffic), waits
// WAIT_S seconds of real time for the rerun web viewer to load and lay out, then saves one
// PNG per size (the page is resized in place, and given a few seconds to re-layout).
import puppeteer from "puppeteer-core";

const [url, waitS, ...shots] = process.argv.slice(2);
if (!url || !waitS || shots.length === 0) {
  console.error("usage: node shot.mjs URL WAIT_S OUT.png:WIDTHxHEIGHT [...]");
  process.exit(2);
}
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const parse = (spec) => {
  const [path, size] = spec.split(":");
  const [width, height] = size.split("x").map(Number);
  return { path, width, height };
};

const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  const page = await browser.newPage();
  const first = parse(shots[0]);
  await page.setViewport({ width: first.width, height: first.height });
  await page.goto(url, { waitUntil: "domcontentloaded", timeout: 60_000 });
  await sleep(Number(waitS) * 1000);
  for (const [i, spec] of shots.entries()) {
    const { path, width, height } = parse(spec);
    if (i > 0) {
      await page.setViewport({ width, height });
      await sleep(8000);
    }
    await page.screenshot({ path });
    console.log(`saved ${path} (${width}x${height})`);
  }
} finally {
  await browser.close();
}
