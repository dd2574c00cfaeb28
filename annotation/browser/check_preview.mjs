// Headless-browser check of a HIT preview: `node check_preview.mjs PREVIEW.html SHOT.png`.
// Chromium comes from the npm registry (@sparticuz/chromium bundles the binary), so no browser
// download host is needed. Network requests other than file:// are blocked, as on an offline
// machine: the page must work without the crowd-html-elements script. Prints one JSON object
// with what a worker would see; exits 1 when the page does not render its items.
import chromium from "@sparticuz/chromium";
import puppeteer from "puppeteer-core";
import { pathToFileURL } from "node:url";
import { resolve } from "node:path";

const [page_path, shot_path] = process.argv.slice(2);
if (!page_path || !shot_path) {
  console.error("usage: node check_preview.mjs PREVIEW.html SHOT.png");
  process.exit(2);
}
const browser = await puppeteer.launch({
  args: chromium.args,
  executablePath: await chromium.executablePath(),
  headless: true,
  defaultViewport: { width: 1000, height: 800 },
});
try {
  const page = await browser.newPage();
  await page.setRequestInterception(true);
  page.on("request", (req) => (req.url().startsWith("file:") ? req.continue() : req.abort()));
  await page.goto(pathToFileURL(resolve(page_path)).href, { waitUntil: "load" });
  const seen = await page.evaluate(() => {
    const visible = (el) => el.getBoundingClientRect().height > 0;
    const items = [...document.querySelectorAll(".item")].map((item) => {
      const radios = [...item.querySelectorAll("input[type=radio]")];
      return {
        sentence: item.querySelector(".sentence")?.innerText.trim() ?? "",
        visible: visible(item),
        radios: radios.filter(visible).map((r) => `${r.name}=${r.value}`),
        required: radios.some((r) => r.required),
      };
    });
    // Clicking the first radio of each item must select exactly that answer (names do not collide).
    const radios = [...document.querySelectorAll(".item")].map((item) => item.querySelector("input[type=radio]"));
    radios.forEach((r) => r.click());
    const checked = [...document.querySelectorAll("input[type=radio]:checked")].map((r) => r.name);
    return { items, checked, unfilled: document.body.innerText.includes("${") };
  });
  await page.screenshot({ path: shot_path, fullPage: true });
  console.log(JSON.stringify(seen));
  process.exitCode = seen.items.length && !seen.unfilled ? 0 : 1;
} finally {
  await browser.close();
}
