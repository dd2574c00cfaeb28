// The page of `lmcr serve`: objects and an instruction in, the frame, the completion, the robot's question
// and the simulated execution out. The server keeps no conversation: what the robot asked (`pending`)
// comes back with each answer. document.body.dataset.state says where the page is (idle, busy, asked,
// done, error), for people's scripts and the headless-browser test.
"use strict";

const $ = (id) => document.getElementById(id);
let asked = null; // {instruction, objects, seed, pending} while the robot waits for an answer
let recorder = null; // the running recording, if any
let understood = null; // {said, missing}: the frame as said and its missing roles, from the completion

function setState(state, status = "") {
  document.body.dataset.state = state;
  $("status").textContent = status;
  const busy = state === "busy";
  for (const id of ["ask", "record", "send-answer"]) $(id).disabled = busy && !(id === "record" && recorder);
}

// The robot's own sentence when it did not understand ("Sorry, I don't know how to juggle."), else the reason.
function showError(error) {
  $("error").textContent = error.reply || error.message;
  $("error").title = error.message;
  $("error").hidden = false;
  setState("error");
}

async function call(path, body, headers = { "Content-Type": "application/json" }) {
  const response = await fetch(path, { method: "POST", headers, body });
  let data;
  try {
    data = await response.json();
  } catch {
    throw new Error(`the server answered ${response.status} without JSON`);
  }
  if (!response.ok) {
    const error = new Error(data.error || `the server answered ${response.status}`);
    error.reply = data.reply;
    throw error;
  }
  return data;
}

function objectsTyped() {
  return $("objects").value.split(",").map((o) => o.trim().toLowerCase()).filter(Boolean);
}

function scene() {
  return { instruction: $("instruction").value, objects: objectsTyped(), seed: Number($("seed").value) || 0 };
}

function say(who, text) {
  const line = document.createElement("p");
  line.className = who;
  line.textContent = text;
  $("conversation").append(line);
}

function renderFrame(said, filled, missing) {
  const box = $("frame");
  box.replaceChildren();
  const name = document.createElement("span");
  name.className = "predicate";
  name.textContent = said.predicate;
  box.append(name, " ");
  for (const [role, value] of Object.entries(filled)) {
    const part = document.createElement("span");
    part.className = "role";
    part.dataset.role = role;
    const shown = document.createElement("span");
    shown.className = missing.includes(role) ? "filled" : "";
    shown.textContent = value ?? "?";
    part.append(`${role}: `);
    if (missing.includes(role)) {
      const gap = document.createElement("span");
      gap.className = "missing";
      gap.textContent = "? → ";
      part.append(gap);
    }
    part.append(shown);
    box.append(part);
  }
}

function renderCandidates(candidates, missing, chosen) {
  const rows = $("candidates").querySelector("tbody");
  rows.replaceChildren();
  for (const c of candidates) {
    const row = document.createElement("tr");
    const name = missing.map((role) => c.objects[role]).join(" → ");
    row.className = missing.every((role) => c.objects[role] === chosen[role]) ? "chosen candidate" : "candidate";
    const cell = document.createElement("td");
    cell.className = "object";
    cell.textContent = name;
    const prob = document.createElement("td");
    prob.className = "probability";
    const bar = document.createElement("div");
    bar.className = "bar";
    const fill = document.createElement("span");
    fill.style.width = `${(100 * c.probability).toFixed(1)}%`;
    const label = document.createElement("b");
    label.textContent = c.probability.toFixed(2);
    bar.append(fill, label);
    prob.append(bar);
    row.append(cell, prob);
    rows.append(row);
  }
  $("candidates").hidden = candidates.length === 0;
}

function showActedOn(roles) {
  renderFrame(understood.said, roles, understood.missing);
  const chosen = understood.missing.map((role) => roles[role]).join(" → ");
  for (const row of $("candidates").querySelectorAll("tbody tr")) {
    row.classList.toggle("chosen", row.querySelector(".object").textContent === chosen);
  }
}

function askAnswer(request, pending) {
  asked = { ...request, pending };
  say("robot", pending.question);
  $("answer-box").hidden = false;
  $("answer").value = "";
  $("answer").focus();
  setState("asked", "The robot is waiting for your answer.");
}

async function ask() {
  $("error").hidden = true;
  $("execution").hidden = true;
  $("answer-box").hidden = true;
  asked = null;
  const request = scene();
  setState("busy", "Reading the instruction (the first request loads the models)…");
  let result;
  try {
    result = await call("/api/complete", JSON.stringify(request));
  } catch (error) {
    $("result").hidden = true;
    return showError(error);
  }
  request.instruction = result.instruction;
  $("result").hidden = false;
  $("conversation").replaceChildren();
  say("you", result.instruction);
  understood = { said: result.said, missing: result.missing_roles };
  renderFrame(result.said, result.frame.roles, result.missing_roles);
  renderCandidates(result.candidates, result.missing_roles, result.frame.roles);
  $("calibration").textContent = result.missing_roles.length ? `probabilities: ${result.calibration}` : "nothing was missing";
  if (result.pending) return askAnswer(request, result.pending);
  return execute(request, null);
}

async function answer(event) {
  event.preventDefault();
  const reply = $("answer").value.trim();
  if (!reply || !asked) return;
  say("you", reply);
  setState("busy", "Reading your answer…");
  let read;
  try {
    read = await call("/api/answer", JSON.stringify({ reply, pending: asked.pending }));
  } catch (error) {
    return showError(error);
  }
  if (read.answer) {
    $("answer-box").hidden = true;
    const request = asked;
    asked = null;
    return execute(request, read.answer);
  }
  if (read.left) {
    $("answer-box").hidden = true;
    asked = null;
    say("robot", read.said);
    return setState("done", "");
  }
  say("robot", read.said);
  asked.pending = read.pending;
  $("answer").value = "";
  setState("asked", "The robot is waiting for your answer.");
}

async function execute(request, answered) {
  setState("busy", "The robot is planning and moving (this takes a while)…");
  let result;
  try {
    const { instruction, objects, seed } = request;
    result = await call("/api/execute", JSON.stringify({ instruction, objects, seed, answer: answered }));
  } catch (error) {
    return showError(error);
  }
  $("execution").hidden = false;
  const reply = $("reply");
  reply.textContent = result.reply;
  reply.className = `reply ${result.success ? "success" : "failure"}`;
  if (!result.pending) say("robot", result.reply);
  if (result.feasible) showActedOn(result.frame.roles); // an answer or an offer taken may differ from the completion
  renderChecks(result);
  if (result.animation) {
    $("animation-figure").hidden = false;
    $("animation").src = `/api/animation/${result.animation}.gif`;
    $("captions").textContent = result.captions.join(" · ");
  } else {
    $("animation-figure").hidden = true;
    $("animation").removeAttribute("src");
  }
  if (result.pending) return askAnswer(request, result.pending);
  setState("done", "");
}

function renderChecks(result) {
  const rows = [["success", result.success ? "yes" : "no"], ["arm", result.arm ?? "none (nothing moved)"]];
  for (const w of result.waypoints) rows.push([w.name, `${(1000 * w.error_m).toFixed(1)} mm from the plan`]);
  if (result.seconds) rows.push(["time", `${result.seconds.plan} s planning, ${result.seconds.execute} s moving`]);
  const list = $("checks");
  list.replaceChildren();
  for (const [name, value] of rows) {
    const dt = document.createElement("dt");
    dt.textContent = name;
    const dd = document.createElement("dd");
    dd.textContent = value;
    list.append(dt, dd);
  }
}

// Recording: 16-bit PCM mono WAV made here from Web Audio samples, so the server decodes it without ffmpeg.
async function toggleRecording() {
  if (recorder) return stopRecording();
  $("error").hidden = true;
  let stream;
  try {
    stream = await navigator.mediaDevices.getUserMedia({ audio: true });
  } catch (error) {
    return showError(new Error(`cannot use the microphone: ${error.message}`));
  }
  const context = new AudioContext();
  const source = context.createMediaStreamSource(stream);
  const node = context.createScriptProcessor(4096, 1, 1);
  const chunks = [];
  let samples = 0;
  node.onaudioprocess = (event) => {
    chunks.push(new Float32Array(event.inputBuffer.getChannelData(0)));
    samples += event.inputBuffer.length;
    const seconds = (samples / context.sampleRate).toFixed(1);
    document.body.dataset.recorded = seconds;
    $("status").textContent = `Recording… ${seconds} s. Click Stop when you are done.`;
  };
  source.connect(node);
  node.connect(context.destination);
  recorder = { stream, context, node, chunks };
  $("record").classList.add("recording");
  $("record").textContent = "■ Stop";
  document.body.dataset.recorded = "0.0";
  setState("busy", "Recording… click Stop when you are done.");
}

async function stopRecording() {
  const { stream, context, node, chunks } = recorder;
  recorder = null;
  node.disconnect();
  stream.getTracks().forEach((track) => track.stop());
  await context.close();
  $("record").classList.remove("recording");
  $("record").innerHTML = "&#9679; Record";
  setState("busy", "Listening to the recording…");
  const wav = encodeWav(chunks, context.sampleRate);
  let heard;
  try {
    const objects = encodeURIComponent(objectsTyped().join(","));
    heard = await call(`/api/listen?objects=${objects}`, wav, { "Content-Type": "audio/wav" });
  } catch (error) {
    return showError(error);
  }
  if (!heard.text) return showError(new Error(`nothing heard: ${heard.reason || "try again, closer to the microphone"}`));
  $("instruction").value = heard.text;
  if (heard.question) return setState("idle", `Heard "${heard.text}". ${heard.question} Correct the text, then ask.`);
  return ask();
}

function encodeWav(chunks, rate) {
  const length = chunks.reduce((n, c) => n + c.length, 0);
  const buffer = new ArrayBuffer(44 + 2 * length);
  const view = new DataView(buffer);
  const text = (offset, s) => [...s].forEach((ch, i) => view.setUint8(offset + i, ch.charCodeAt(0)));
  text(0, "RIFF");
  view.setUint32(4, 36 + 2 * length, true);
  text(8, "WAVE");
  text(12, "fmt ");
  view.setUint32(16, 16, true);
  view.setUint16(20, 1, true); // PCM
  view.setUint16(22, 1, true); // mono
  view.setUint32(24, rate, true);
  view.setUint32(28, 2 * rate, true);
  view.setUint16(32, 2, true);
  view.setUint16(34, 16, true);
  text(36, "data");
  view.setUint32(40, 2 * length, true);
  let offset = 44;
  for (const chunk of chunks) {
    for (const sample of chunk) {
      const s = Math.max(-1, Math.min(1, sample));
      view.setInt16(offset, s < 0 ? s * 0x8000 : s * 0x7fff, true);
      offset += 2;
    }
  }
  return new Blob([buffer], { type: "audio/wav" });
}

function renderVocabulary(words) {
  const box = $("vocabulary");
  for (const word of words) {
    const chip = document.createElement("button");
    chip.type = "button";
    chip.className = "chip";
    chip.textContent = word;
    chip.addEventListener("click", () => {
      const objects = objectsTyped();
      const next = objects.includes(word) ? objects.filter((o) => o !== word) : [...objects, word];
      $("objects").value = next.join(", ");
      syncChips();
    });
    box.append(chip);
  }
}

function syncChips() {
  const on = new Set(objectsTyped());
  for (const chip of $("vocabulary").children) chip.classList.toggle("on", on.has(chip.textContent));
}

async function start() {
  $("ask").addEventListener("click", ask);
  $("instruction").addEventListener("keydown", (e) => e.key === "Enter" && !$("ask").disabled && ask());
  $("answer-box").addEventListener("submit", answer);
  $("record").addEventListener("click", toggleRecording);
  $("objects").addEventListener("input", syncChips);
  if (!navigator.mediaDevices || !window.AudioContext) $("record").hidden = true;
  try {
    const response = await fetch("/api/vocabulary");
    const vocabulary = await response.json();
    renderVocabulary(vocabulary.objects);
    if (!$("objects").value) $("objects").value = vocabulary.example.objects.join(", ");
    if (!$("instruction").value) $("instruction").placeholder = vocabulary.example.instruction;
    syncChips();
  } catch (error) {
    return showError(new Error(`cannot reach the server: ${error.message}`));
  }
  setState("idle");
}

start();
