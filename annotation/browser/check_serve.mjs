// Headless-browser check of `lmcr serve`'s page:
//   node check_serve.mjs URL SHOT.png OBJECTS INSTRUCTION ANSWER
// Opens the page, asks with an empty instruction (the error must show), then types the objects and the
// instruction, asks, answers the robot's question with ANSWER when it asks, waits for the execution's
// animation and saves a full-page screenshot. Requests to anything but the server are blocked, as on an
// offline machine. Prints one JSON object with what a person would see; exits 1 when the page ends in
// an error or without an animation.
import chromium from "@sparticuz/chromium";
import puppeteer from "puppeteer-core";
import { readFileSync } from "node:fs";

const [url, shot, objects, instruction, answer, spoken] = process.argv.slice(2);
if (!url || !shot || !objects || !instruction || !answer) {
  console.error("usage: node check_serve.mjs URL SHOT.png OBJECTS INSTRUCTION ANSWER [SPOKEN.wav]");
  process.exit(2);
}
// With SPOKEN.wav, the microphone is that file (played once): the page records it and the server hears it.
const microphone = spoken ? ["--use-fake-ui-for-media-stream", "--use-fake-device-for-media-stream",
  `--use-file-for-fake-audio-capture=${spoken}%noloop`] : [];
const RUN_MS = 300_000; // the first request loads the models; planning and simulating take a while more
const origin = new URL(url).origin;
const browser = await puppeteer.launch({
  args: [...chromium.args, ...microphone],
  executablePath: await chromium.executablePath(),
  headless: true,
  defaultViewport: { width: 1100, height: 900 },
});

const settled = (states) => `[${states.map((s) => JSON.stringify(s)).join(",")}].includes(document.body.dataset.state)`;

async function type(page, selector, text) {
  await page.$eval(selector, (el) => (el.value = ""));
  await page.type(selector, text);
}

function wavSeconds(path) {
  const bytes = readFileSync(path);
  return bytes.readUInt32LE(bytes.indexOf("data") + 4) / bytes.readUInt32LE(28); // data size / byte rate
}

// Record the fake microphone's file with the page's Record button, stop once the page has recorded all of
// it, and let the page hear it and go on with what it heard.
async function record(page) {
  await page.$eval("#instruction", (el) => (el.value = ""));
  await page.click("#record");
  await page.waitForFunction((s) => Number(document.body.dataset.recorded) >= s, { timeout: 60_000 },
    wavSeconds(spoken) + 0.5);
  await page.click("#record");
  await page.waitForFunction(() => document.getElementById("instruction").value !== "" ||
    document.body.dataset.state === "error", { timeout: RUN_MS });
  const text = await page.$eval("#instruction", (el) => el.value);
  await page.waitForFunction(settled(["asked", "done", "error"]), { timeout: RUN_MS });
  const error = await page.$eval("#error", (el) => (el.hidden ? "" : el.textContent));
  return { text, state: await page.evaluate(() => document.body.dataset.state), error };
}

try {
  const page = await browser.newPage();
  const failed = [];
  page.on("requestfailed", (req) => req.url().startsWith(origin) && failed.push(req.url()));
  await page.setRequestInterception(true);
  page.on("request", (req) => (req.url().startsWith(origin) ? req.continue() : req.abort()));
  await page.goto(url, { waitUntil: "load" });
  await page.waitForFunction(settled(["idle"]), { timeout: 30_000 });
  const chips = await page.$$eval("#vocabulary .chip", (els) => els.length);

  await type(page, "#instruction", " ");
  await page.click("#ask");
  await page.waitForFunction(settled(["error"]), { timeout: 30_000 });
  const emptyError = await page.$eval("#error", (el) => (el.hidden ? "" : el.textContent));

  await type(page, "#objects", objects);
  await type(page, "#instruction", instruction);
  await page.click("#ask");
  await page.waitForFunction(settled(["asked", "done", "error"]), { timeout: RUN_MS });
  const question = await page.$eval("#answer-box", (el) => !el.hidden) ?
    await page.$eval("#conversation .robot:last-child", (el) => el.textContent) : null;
  if (question) {
    await type(page, "#answer", answer);
    await page.click("#send-answer");
    await page.waitForFunction(settled(["done", "error"]), { timeout: RUN_MS });
  }
  await page.waitForFunction(() => {
    const img = document.getElementById("animation");
    return document.body.dataset.state === "error" || (img.getAttribute("src") && img.complete);
  }, { timeout: 30_000 });

  const seen = await page.evaluate(() => {
    const text = (id) => document.getElementById(id)?.textContent.trim() ?? "";
    const img = document.getElementById("animation");
    return {
      state: document.body.dataset.state,
      error: document.getElementById("error").hidden ? "" : text("error"),
      predicate: document.querySelector("#frame .predicate")?.textContent ?? "",
      roles: Object.fromEntries([...document.querySelectorAll("#frame .role")].map((el) =>
        [el.dataset.role, el.lastChild.textContent])),
      filled: [...document.querySelectorAll("#frame .filled")].map((el) => el.textContent),
      candidates: [...document.querySelectorAll("#candidates tbody tr")].map((row) => ({
        object: row.querySelector(".object").textContent,
        probability: Number(row.querySelector(".bar b").textContent),
        chosen: row.classList.contains("chosen"),
      })),
      conversation: [...document.querySelectorAll("#conversation p")].map((p) => `${p.className}: ${p.textContent}`),
      reply: text("reply"),
      animation: { src: img.getAttribute("src") ?? "", width: img.naturalWidth, height: img.naturalHeight },
      captions: text("captions"),
    };
  });
  await page.screenshot({ path: shot, fullPage: true });
  const heard = spoken ? await record(page) : null;
  console.log(JSON.stringify({ ...seen, chips, empty_error: emptyError, question, heard, failed }));
  process.exitCode = seen.state === "done" && seen.animation.width > 0 ? 0 : 1;
} finally {
  await browser.close();
}
