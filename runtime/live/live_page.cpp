// The live view's page: one HTML document with its style and script inline (it fetches nothing but the
// server's own /frame.png and /stats.json).
//
// Frames are long-polled as PNG (/frame.png?after=N answers with the first frame newer than N, or 204 after a
// second): the script knows each frame's index (X-Frame header), draws it on a canvas and asks for the next only
// then, so a slow link or a busy browser gets fewer frames instead of a growing backlog, and every request is
// an ordinary short GET that SSH tunnels and proxies pass unchanged.
//
// With --device browser the page also opens a WebSocket at /ws and becomes the device (docs/browser-device.md):
// the pointer drags the tool on the view plane, the wheel sets its depth, Space / a right press / a long press is
// the button, a gamepad's sticks and triggers do the same; the device force comes back and is drawn as an arrow.
#include "runtime/live/live_server.h"

namespace palpate {

const std::string& live_page_html() {
  static const std::string page = R"PAGE(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>palpate live</title>
<style>
body { font: 13px system-ui, sans-serif; margin: 12px; background: #f3f3f1; color: #222; }
h1 { font-size: 16px; margin: 0 0 8px 0; font-weight: 600; }
#state { padding: 1px 6px; border-radius: 3px; background: #ddd; font-weight: 600; }
#state.running { background: #c8e6c9; } #state.finished { background: #bbdefb; } #state.gone { background: #ffcdd2; }
#top { display: flex; gap: 14px; flex-wrap: wrap; align-items: flex-start; }
#view { background: #000; max-width: 100%; height: auto; display: block; }
#stage { position: relative; touch-action: none; user-select: none; }
#overlay { position: absolute; left: 0; top: 0; width: 100%; height: 100%; cursor: crosshair; }
#device { margin: 6px 0; display: none; } #device b { padding: 1px 6px; border-radius: 3px; background: #ddd; }
#device b.control { background: #ffe0b2; } #device b.watch { background: #e0e0e0; }
#controls { margin-top: 6px; display: none; } #controls label { margin-right: 8px; white-space: nowrap; }
#controls input[type=range] { width: 140px; vertical-align: middle; } #ctlmsg { color: #b71c1c; }
table { border-collapse: collapse; background: #fff; }
td { padding: 3px 10px; border-bottom: 1px solid #e4e4e4; }
td.v { text-align: right; font-variant-numeric: tabular-nums; }
#plots { display: grid; grid-template-columns: repeat(2, minmax(280px, 1fr)); gap: 8px; margin-top: 12px; }
canvas.plot { background: #fff; border: 1px solid #ccc; width: 100%; height: 150px; }
</style>
</head>
<body>
<h1>palpate live &middot; <span id="scene">&hellip;</span> <span id="state">connecting</span></h1>
<div id="top">
  <div><div id="stage"><canvas id="view" width="640" height="480"></canvas><canvas id="overlay"></canvas></div>
  <div id="device">device: <b id="role">&hellip;</b> <span id="devinfo"></span><br>
  drag: move the tool from where it is &middot; wheel or two fingers: depth &middot; [ ]: wheel step &middot; Space, right button or a long press: button (grab / blade)
  <div id="controls">mode: <span id="modes"></span>
  <label>stiffness <input type="range" id="stiff" min="0" max="1000"> <span id="stiffv"></span></label>
  <label>tool radius <input type="range" id="radius" min="0" max="1000"> <span id="radiusv"></span></label>
  <button id="reset" type="button">reset the model</button> <span id="ctlmsg"></span></div></div></div>
  <table><tbody id="figures"></tbody></table>
</div>
<div id="plots">
  <canvas class="plot" id="plot-force"></canvas>
  <canvas class="plot" id="plot-contact"></canvas>
  <canvas class="plot" id="plot-wake"></canvas>
  <canvas class="plot" id="plot-frame"></canvas>
</div>
<script>
"use strict";
// what the page has seen, for people and for scripts driving a browser
const live = { framesDrawn: 0, lastFrame: -1, forcePoints: 0, finished: false, connected: false, stats: null };
window.live = live;
const $ = (id) => document.getElementById(id);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const WINDOW_S = 10;  // scene seconds shown in the plots
const s = { t: [], force: [], contact: [], wake: [], work: [], late: [] };
let next = 0;
let deviceOn = false;  // the server steers a browser device through this page

async function frames() {
  const view = $("view"), ctx = view.getContext("2d");
  for (;;) {
    try {
      const r = await fetch("/frame.png?after=" + live.lastFrame, { cache: "no-store" });
      live.connected = true;
      if (r.status === 200) {
        const index = Number(r.headers.get("X-Frame"));
        const bmp = await createImageBitmap(await r.blob());
        if (view.width !== bmp.width || view.height !== bmp.height) { view.width = bmp.width; view.height = bmp.height; }
        ctx.drawImage(bmp, 0, 0);
        bmp.close();
        live.lastFrame = index;
        live.framesDrawn++;
        frameDrawn(index);
      } else if (r.status !== 204) {
        await sleep(500);
      }
    } catch (e) {
      live.connected = false;
      showState();
      await sleep(1000);
    }
  }
}

function fmt(x, d) { return x === undefined || x === null ? "" : Number(x).toFixed(d); }

function showFigures(j) {
  const rows = [
    ["scene", j.scene], ["mode", j.mode], ["scene time", fmt(j.t_s, 2) + " s"],
    ["frames", j.frames], ["frames written", j.frames_written], ["frames dropped", j.frames_dropped],
    ["frames late", j.frames_late], ["frame shown", live.lastFrame],
    ["servo ticks", j.servo.ticks], ["servo wake p50", fmt(j.servo.p50_us, 0) + " \u00b5s"],
    ["servo wake p99", fmt(j.servo.p99_us, 0) + " \u00b5s"], ["servo overruns", j.servo.overruns],
    ["max force", fmt(j.max_force_N, 2) + " N"],
  ];
  if (j.browser) {
    const b = j.browser, ms = (x) => x && x.n ? fmt(x.p50, 1) + " / " + fmt(x.p99, 1) + " ms" : "";
    rows.push(["pages (control + watch)", b.pages], ["device messages", b.messages],
              ["input \u2192 force, server p50/p99", b.input_to_force_us.n ? fmt(b.input_to_force_us.p50 / 1000, 2) + " / " +
                fmt(b.input_to_force_us.p99 / 1000, 2) + " ms" : ""],
              ["input \u2192 force back, page p50/p99", ms(b.page_input_to_force_ms)],
              ["input \u2192 frame, page p50/p99", ms(b.page_input_to_frame_ms)]);
  }
  const body = $("figures");
  body.textContent = "";
  for (const [k, v] of rows) {
    const tr = document.createElement("tr");
    const a = document.createElement("td"), b = document.createElement("td");
    a.textContent = k; b.textContent = v; b.className = "v";
    tr.append(a, b); body.append(tr);
  }
  $("scene").textContent = j.scene;
}

function showState() {
  const el = $("state");
  if (!live.connected && live.stats) {
    el.textContent = "server stopped (last frame kept)" + (live.stats.out ? "; outputs in " + live.stats.out : ""); el.className = "gone";
  }
  if ((live.finished || (!live.connected && live.stats)) && deviceOn && !dev.ended) ended(live.stats && live.stats.out);
  else if (!live.connected) { el.textContent = "connecting"; el.className = ""; }
  else if (live.finished) { el.textContent = "finished" + (live.stats && live.stats.out ? ": outputs in " + live.stats.out : ""); el.className = "finished"; }
  else { el.textContent = "recording"; el.className = "running"; }
}

// one plot over the last WINDOW_S scene seconds; returns how many points it drew
function plot(id, title, unit, lines, fixedMax) {
  const c = $(id), dpr = window.devicePixelRatio || 1;
  const w = Math.max(1, Math.round(c.clientWidth * dpr)), h = Math.max(1, Math.round(c.clientHeight * dpr));
  if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
  const g = c.getContext("2d");
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  const W = w / dpr, H = h / dpr, L = 46, R = 8, T = 20, B = 18;
  g.clearRect(0, 0, W, H);
  const t1 = s.t.length ? s.t[s.t.length - 1] : 0, t0 = Math.max(0, t1 - WINDOW_S), span = Math.max(t1 - t0, 1e-3);
  let ymax = fixedMax || 0;
  if (!fixedMax) for (const ln of lines) for (const y of ln.y) ymax = Math.max(ymax, y);
  if (!(ymax > 0)) ymax = 1;
  if (!fixedMax) ymax *= 1.1;
  const X = (t) => L + (W - L - R) * (t - t0) / span, Y = (y) => H - B - (H - T - B) * y / ymax;
  g.strokeStyle = "#e6e6e6"; g.fillStyle = "#666"; g.font = "11px system-ui, sans-serif"; g.lineWidth = 1;
  for (let i = 0; i <= 4; ++i) {
    const y = ymax * i / 4;
    g.beginPath(); g.moveTo(L, Y(y)); g.lineTo(W - R, Y(y)); g.stroke();
    g.fillText(String(Number(y.toPrecision(3))), 2, Y(y) + 4);
  }
  g.fillText(t0.toFixed(1) + " s", L, H - 4);
  g.fillText(t1.toFixed(1) + " s", W - R - 40, H - 4);
  let drawn = 0, label = title;
  for (const ln of lines) {
    g.strokeStyle = ln.color; g.lineWidth = 1.5; g.beginPath();
    let first = true;
    for (let i = 0; i < s.t.length; ++i) {
      if (s.t[i] < t0) continue;
      const x = X(s.t[i]), y = Y(ln.y[i]);
      if (first) { g.moveTo(x, y); first = false; } else g.lineTo(x, y);
      ++drawn;
    }
    g.stroke();
    if (ln.y.length) label += "   " + ln.name + " " + ln.y[ln.y.length - 1].toFixed(ln.digits) + " " + unit;
  }
  g.fillStyle = "#222"; g.font = "12px system-ui, sans-serif";
  g.fillText(label, L, 14);
  return drawn;
}

function drawPlots() {
  live.forcePoints = plot("plot-force", "device force (largest per frame)", "N", [{ y: s.force, color: "#d62728", name: "now", digits: 2 }]);
  plot("plot-contact", "contact (0 free, 1 touch, 2 grab, 3 cut)", "", [{ y: s.contact, color: "#2ca02c", name: "now", digits: 0 }], 3);
  plot("plot-wake", "servo wake latency (worst per frame)", "\u00b5s", [{ y: s.wake, color: "#1f77b4", name: "now", digits: 0 }]);
  plot("plot-frame", "frame work / start late", "ms", [{ y: s.work, color: "#9467bd", name: "work", digits: 1 },
                                                        { y: s.late, color: "#ff7f0e", name: "late", digits: 1 }]);
}

async function stats() {
  for (;;) {
    let more = false;
    try {
      const r = await fetch("/stats.json?since=" + next, { cache: "no-store" });
      const j = await r.json();
      const p = j.points;
      for (let i = 0; i < p.t_s.length; ++i) {
        s.t.push(p.t_s[i]); s.force.push(p.force_N[i]); s.contact.push(p.contact[i]);
        s.wake.push(p.wake_max_us[i]); s.work.push(p.frame_ms[i]); s.late.push(p.late_ms[i]);
      }
      more = j.next - next >= 3600;
      next = j.next;
      // keep what the plots show
      const t1 = s.t.length ? s.t[s.t.length - 1] : 0;
      let cut = 0;
      while (cut < s.t.length && s.t[cut] < t1 - WINDOW_S) ++cut;
      if (cut > 0) for (const k in s) s[k].splice(0, cut);
      live.stats = j; live.finished = j.finished; live.connected = true;
      showFigures(j);
      drawPlots();
    } catch (e) {
      live.connected = false;
    }
    showState();
    if (!more) await sleep(250);
  }
}

// ---- the page as a device (only when the server steers a browser device: /ws answers) ----
// Input is relative: a drag moves the tool from where it is, the wheel steps its depth by dev.wheelMm. The page sends
// poses only while its user steers (an input in the last HOLD_MS, or a button, a press or a stick held) and never
// from a hidden tab; otherwise it sends "k" now and then to keep its socket. The server anchors each page's control
// where the tool is, so a page that connects, reloads or takes over moves nothing until its user does.
const HOLD_MS = 2000;
const dev = { role: "none", steer: true, x: 0, y: 0, depth: 0, button: false, seq: 0, force: [0, 0, 0], fv: [0, 0, 0],
              hv: [0, 0, 0], hs: [0, 0], mm: [0, 0, 0], scale: 0, engaged: false, sent: 0, feedback: 0, inputAt: 0,
              pending: [], frameWait: [], forceMs: -1, frameMs: -1, activeUntil: 0, synced: false, wheelMm: 1.0, sendMs: 15,
              ended: null, alive: 0, ticks: 0, limits: null, controls: null, awaitControls: 0, fbControls: 0 };
live.device = dev;
let sock = null;
function clamp(v) { return Math.max(-1, Math.min(1, v)); }
function visible() { return document.visibilityState !== "hidden"; }
// the page's pointer starts where the tool is (the newest feedback), once per control
function sync() {
  // (the servo has not run yet, or the device has not taken the last change of the controls: where the tool is is
  // not known)
  if (dev.synced || !dev.ticks || dev.fbControls < dev.awaitControls) return;
  dev.x = clamp(dev.hv[0]); dev.y = clamp(dev.hv[1]); dev.depth = clamp(dev.hv[2]);
  dev.synced = true;
  sendPose();  // the anchor: where the tool is, before this input moves it
}
// an input event: the page steers for HOLD_MS more, and its time is kept for the latency figures
function moved() { const now = performance.now(); dev.inputAt = now; dev.activeUntil = now + HOLD_MS; }
function steering() {
  return visible() && !dev.ended && dev.steer && (performance.now() < dev.activeUntil || dragging || keyDown || padActive);
}
function frameDrawn(index) {
  const now = performance.now();
  while (dev.frameWait.length && dev.frameWait[0].k < index) { dev.frameMs = now - dev.frameWait.shift().t; }
}
function ended(out) {
  dev.ended = out || "(the run's output folder)";
  dev.force = [0, 0, 0]; dev.fv = [0, 0, 0]; dev.scale = 0; dev.button = false; dev.activeUntil = 0;
  drawForce();
}
function connectDevice() {
  const token = new URLSearchParams(location.search).get("token");
  sock = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws" +
                       (token ? "?token=" + encodeURIComponent(token) : ""));
  sock.onmessage = (e) => {
    const m = JSON.parse(e.data);
    if (m.t === "hello") {
      dev.role = m.role; dev.steer = m.steer !== false; dev.synced = false;
      if (m.send_ms > 0 && m.send_ms !== dev.sendMs) { clearInterval(sendTimer); dev.sendMs = m.send_ms; sendTimer = setInterval(send, m.send_ms); }
      $("device").style.display = "block";
      $("role").textContent = !dev.steer ? "watching: " + (m.why || "this page may not steer")
          : m.role === "control" ? "you steer it" : "watching (another page steers; steer here once it stops)";
      $("role").className = m.role;
      if (m.limits) showControls(m.limits, m.controls);
      return;
    }
    if (m.t === "controls") {
      // the model starts again: the tool is back where it waited. The page says it heard (the server passes none of
      // its poses on until then: they were made from where the tool was), and starts its pointer where the tool went
      // once the feedback says the device has taken the change
      dev.controls = m.controls; dev.synced = false; dev.awaitControls = m.controls.seq; $("ctlmsg").textContent = "";
      if (dev.role === "control" && sock && sock.readyState === 1) sock.send("a " + m.controls.seq);
      showControls(dev.limits, m.controls);
      return;
    }
    if (m.t === "refused") { $("ctlmsg").textContent = "refused: " + m.why; return; }
    if (m.t === "ended") { ended(m.out); return; }
    if (dev.ended) return;
    dev.force = m.f; dev.fv = m.fv; dev.hv = m.hv; dev.hs = m.hs || [m.hv[0], m.hv[1]]; dev.mm = m.mm || dev.mm;
    dev.scale = m.scale; dev.engaged = !!m.e; dev.ticks = m.n || 0; dev.feedback++; dev.fbControls = m.c || 0;
    // the first feedback that used a message carrying an input event: event to force computed and back
    const now = performance.now();
    while (dev.pending.length && dev.pending[0].seq <= m.s) {
      const p = dev.pending.shift();
      if (dev.role === "control") { dev.forceMs = now - p.t; dev.frameWait.push({ k: m.k, t: p.t }); }
    }
    if (dev.frameWait.length > 120) dev.frameWait.splice(0, dev.frameWait.length - 120);
    drawForce();
  };
  sock.onclose = () => { dev.role = "none"; $("role").textContent = "not connected"; $("role").className = ""; drawForce(); };
}
// the controls (only the steering page's reach the servo): mode, stiffness within the scene's range (a log scale),
// tool radius within its range, reset. A slider sends when it is let go; every change starts the model again.
function stiffOf(pos, l) { return l.stiffness[0] * Math.pow(l.stiffness[1] / l.stiffness[0], pos / 1000); }
function posOfStiff(k, l) { return l.stiffness[1] > l.stiffness[0] ? 1000 * Math.log(k / l.stiffness[0]) / Math.log(l.stiffness[1] / l.stiffness[0]) : 0; }
function radiusOf(pos, l) { return l.radius_mm[0] + (l.radius_mm[1] - l.radius_mm[0]) * pos / 1000; }
function stiffText(k, l) { return l.young_modulus_kPa > 0 ? "E " + (k * l.young_modulus_kPa).toPrecision(3) + " kPa" : "\u00d7" + k.toPrecision(3); }
function showControls(l, c) {
  if (!l || !c) return;
  dev.limits = l; dev.controls = c;
  $("controls").style.display = "block";
  const modes = $("modes");
  if (!modes.childElementCount)
    for (const name of l.modes) {
      const lab = document.createElement("label"), r = document.createElement("input");
      r.type = "radio"; r.name = "mode"; r.value = name; r.id = "mode-" + name;
      r.addEventListener("change", sendControls);
      lab.appendChild(r); lab.appendChild(document.createTextNode(" " + name)); modes.appendChild(lab);
    }
  for (const r of document.querySelectorAll("input[name=mode]")) r.checked = r.value === c.mode;
  $("stiff").value = posOfStiff(c.stiffness, l); $("stiffv").textContent = stiffText(c.stiffness, l);
  $("radius").value = l.radius_mm[1] > l.radius_mm[0] ? 1000 * (c.radius_mm - l.radius_mm[0]) / (l.radius_mm[1] - l.radius_mm[0]) : 0;
  $("radiusv").textContent = c.radius_mm.toFixed(2) + " mm";
  const mine = dev.role === "control" && dev.steer;
  for (const e of document.querySelectorAll("#controls input, #controls button")) e.disabled = !mine;
}
function sendControls() {
  const l = dev.limits;
  if (!l || !sock || sock.readyState !== 1 || dev.role !== "control") return;
  const picked = document.querySelector("input[name=mode]:checked");
  const k = stiffOf(+$("stiff").value, l), r = radiusOf(+$("radius").value, l);
  sock.send("c " + (picked ? picked.value : dev.controls.mode) + " " + k.toPrecision(6) + " " + r.toFixed(4));
}
function setupControls() {
  $("stiff").addEventListener("input", () => { if (dev.limits) $("stiffv").textContent = stiffText(stiffOf(+$("stiff").value, dev.limits), dev.limits); });
  $("radius").addEventListener("input", () => { if (dev.limits) $("radiusv").textContent = radiusOf(+$("radius").value, dev.limits).toFixed(2) + " mm"; });
  $("stiff").addEventListener("change", sendControls);
  $("radius").addEventListener("change", sendControls);
  $("reset").addEventListener("click", () => { if (sock && sock.readyState === 1 && dev.role === "control") sock.send("r"); });
}
function sendPose() {
  if (!sock || sock.readyState !== 1 || !dev.steer) return;
  dev.seq++;
  const b = dev.button ? 1 : 0;
  sock.send("p " + dev.seq + " " + dev.x.toFixed(4) + " " + dev.y.toFixed(4) + " " + dev.depth.toFixed(4) + " " + b);
  dev.sent++;
  if (dev.inputAt > 0) { dev.pending.push({ seq: dev.seq, t: dev.inputAt }); dev.inputAt = 0; }
  if (dev.pending.length > 120) dev.pending.splice(0, dev.pending.length - 120);
}
function send() {
  pollGamepad();
  if (!sock || sock.readyState !== 1) return;
  if (steering() && dev.synced) { sendPose(); return; }
  const now = performance.now();
  if (now - dev.alive > 2000) { dev.alive = now; sock.send("k"); }
}
function sendLatency() {
  if (sock && sock.readyState === 1 && dev.role === "control" && (dev.forceMs >= 0 || dev.frameMs >= 0))
    sock.send("l " + Math.min(dev.forceMs, 60000).toFixed(2) + " " + Math.min(dev.frameMs, 60000).toFixed(2));
}
function arrowHead(g, x0, y0, x1, y1) {
  const a = Math.atan2(y1 - y0, x1 - x0);
  g.beginPath(); g.moveTo(x1, y1); g.lineTo(x1 - 9 * Math.cos(a - 0.4), y1 - 9 * Math.sin(a - 0.4));
  g.lineTo(x1 - 9 * Math.cos(a + 0.4), y1 - 9 * Math.sin(a + 0.4)); g.fill();
}
function drawForce() {
  const o = $("overlay"), v = $("view");
  if (o.width !== v.clientWidth || o.height !== v.clientHeight) { o.width = v.clientWidth; o.height = v.clientHeight; }
  const g = o.getContext("2d");
  g.clearRect(0, 0, o.width, o.height);
  g.font = "13px system-ui, sans-serif";
  if (dev.ended) {
    g.fillStyle = "rgba(0,0,0,0.6)"; g.fillRect(0, 0, o.width, 28);
    g.fillStyle = "#fff"; g.fillText("run ended: no force; outputs in " + dev.ended, 8, 18);
    $("devinfo").textContent = "run ended; outputs in " + dev.ended;
    return;
  }
  if (dev.role === "none") return;
  // the tool where the camera sees it (perspective), drawn over the surface (also when it is inside)
  const px = (dev.hs[0] + 1) / 2 * o.width, py = (1 - dev.hs[1]) / 2 * o.height;
  const f = Math.hypot(dev.force[0], dev.force[1], dev.force[2]), s = 40;  // px per N
  g.strokeStyle = "#ff9800"; g.fillStyle = "#ff9800"; g.lineWidth = 3;
  g.beginPath(); g.arc(px, py, 5, 0, 2 * Math.PI); g.stroke();
  g.setLineDash([2, 3]); g.lineWidth = 1; g.beginPath(); g.arc(px, py, 9, 0, 2 * Math.PI); g.stroke(); g.setLineDash([]);
  const ex = px + dev.fv[0] * s, ey = py - dev.fv[1] * s;
  g.lineWidth = 3; g.beginPath(); g.moveTo(px, py); g.lineTo(ex, ey); g.stroke();
  if (f > 0.01) arrowHead(g, px, py, ex, ey);
  // depth gauge at the right edge: near (top) .. far (bottom), the tool's depth marked, in mm from the view plane
  const gx = o.width - 22, gt = 30, gb = o.height - 30, gy = gt + (gb - gt) * (clamp(dev.hv[2]) + 1) / 2;
  g.fillStyle = "rgba(255,255,255,0.75)"; g.fillRect(gx - 6, gt - 4, 16, gb - gt + 8);
  g.strokeStyle = "#555"; g.lineWidth = 1; g.beginPath(); g.moveTo(gx + 2, gt); g.lineTo(gx + 2, gb);
  g.moveTo(gx - 3, (gt + gb) / 2); g.lineTo(gx + 7, (gt + gb) / 2); g.stroke();
  g.fillStyle = "#ff9800"; g.beginPath(); g.moveTo(gx - 8, gy); g.lineTo(gx + 2, gy - 6); g.lineTo(gx + 2, gy + 6); g.fill();
  const depthMm = dev.hv[2] * dev.mm[2];
  g.fillStyle = "#fff"; g.strokeStyle = "#000"; g.lineWidth = 3;
  const label = "F " + f.toFixed(2) + " N" + (dev.button ? "  [button]" : "") + "   depth " +
      (depthMm >= 0 ? "+" : "") + depthMm.toFixed(1) + " mm   wheel " + dev.wheelMm + " mm/notch ([ ])" +
      (dev.role === "control" && !dev.engaged ? "   move to steer" : "") +
      (dev.scale > 0 && dev.scale < 1 ? "  fading " + dev.scale.toFixed(2) : "");
  g.strokeText(label, 8, 18); g.fillText(label, 8, 18);
  $("devinfo").textContent = "force " + f.toFixed(2) + " N, input \u2192 force back " +
      (dev.forceMs >= 0 ? dev.forceMs.toFixed(1) + " ms" : "\u2013") + ", input \u2192 frame " +
      (dev.frameMs >= 0 ? dev.frameMs.toFixed(0) + " ms" : "\u2013");
}
// pointer (mouse, touch, pen): a drag moves the tool by the pointer's motion; a press held still 0.5 s (or the right
// button) is the button; two fingers dragged up or down set the depth
let dragging = false, pressTimer = 0, pressAt = null, keyDown = false, padButton = false, padActive = false;
const touches = new Map();
function setupInput() {
  const o = $("overlay");
  const rect = () => o.getBoundingClientRect();
  o.addEventListener("contextmenu", (e) => e.preventDefault());
  o.addEventListener("pointerdown", (e) => {
    o.setPointerCapture(e.pointerId);
    touches.set(e.pointerId, [e.clientX, e.clientY]);
    sync();
    dragging = true; moved();
    if (e.pointerType === "pen" && e.pressure > 0) dev.depth = clamp(e.pressure * 2 - 1);
    if (e.button === 2) { dev.button = true; return; }
    pressAt = [e.clientX, e.clientY];
    clearTimeout(pressTimer);
    pressTimer = setTimeout(() => { dev.button = true; moved(); }, 500);
  });
  o.addEventListener("pointermove", (e) => {
    const last = touches.get(e.pointerId);
    if (!dragging || !last) return;
    const r = rect(), dx = e.clientX - last[0], dy = e.clientY - last[1];
    touches.set(e.pointerId, [e.clientX, e.clientY]);
    sync();
    if (touches.size >= 2) {
      // two fingers: depth, 0.2 mm a pixel of their vertical drag (each finger moves half)
      if (dev.mm[2] > 0) dev.depth = clamp(dev.depth + 0.1 * dy / dev.mm[2]);
    } else {
      dev.x = clamp(dev.x + 2 * dx / r.width);
      dev.y = clamp(dev.y - 2 * dy / r.height);
      if (e.pointerType === "pen" && e.pressure > 0) dev.depth = clamp(e.pressure * 2 - 1);
    }
    moved();
    if (pressAt && Math.hypot(e.clientX - pressAt[0], e.clientY - pressAt[1]) > 6) { clearTimeout(pressTimer); pressAt = null; }
  });
  const up = (e) => { touches.delete(e.pointerId); if (touches.size) return;
                      dragging = false; clearTimeout(pressTimer); pressAt = null;
                      if (!keyDown) { dev.button = false; moved(); } };
  o.addEventListener("pointerup", up);
  o.addEventListener("pointercancel", up);
  o.addEventListener("wheel", (e) => {
    e.preventDefault();
    sync();
    const notches = e.deltaMode === 1 ? e.deltaY / 3 : e.deltaMode === 2 ? e.deltaY * 10 : e.deltaY / 100;
    if (dev.mm[2] > 0) dev.depth = clamp(dev.depth + notches * dev.wheelMm / dev.mm[2]);
    moved();
  }, { passive: false });
  window.addEventListener("keydown", (e) => {
    if (e.code === "Space") { e.preventDefault(); sync(); keyDown = true; dev.button = true; moved(); }
    if (e.key === "[" || e.key === "]") {
      dev.wheelMm = Math.max(0.25, Math.min(8, e.key === "]" ? dev.wheelMm * 2 : dev.wheelMm / 2)); drawForce();
    }
  });
  window.addEventListener("keyup", (e) => { if (e.code === "Space") { keyDown = false; dev.button = false; moved(); } });
  // a hidden tab lets go: no button, no poses (the server fades the force out and another page may steer)
  document.addEventListener("visibilitychange", () => {
    if (visible()) return;
    dragging = false; keyDown = false; dev.button = false; dev.activeUntil = 0; touches.clear();
  });
}
// gamepad: left stick moves across the view, right stick up/down and the triggers set depth, A or RB is the button;
// the vibration follows the force
function pollGamepad() {
  const pads = navigator.getGamepads ? navigator.getGamepads() : [];
  padActive = false;
  for (const p of pads) {
    if (!p || !p.connected) continue;
    const dz = (v) => Math.abs(v) < 0.12 ? 0 : v, k = 0.02;
    const lx = dz(p.axes[0] || 0), ly = dz(p.axes[1] || 0), ry = dz(p.axes[3] || 0);
    const lt = p.buttons[6] ? p.buttons[6].value : 0, rt = p.buttons[7] ? p.buttons[7].value : 0;
    const b = !!((p.buttons[0] && p.buttons[0].pressed) || (p.buttons[5] && p.buttons[5].pressed));
    if (lx || ly || ry || lt || rt || b) {
      sync();
      padActive = visible();
      dev.x = clamp(dev.x + k * lx); dev.y = clamp(dev.y - k * ly);
      dev.depth = clamp(dev.depth + k * (ry + rt - lt)); moved();
    }
    if (b !== padButton) { padButton = b; dev.button = b; moved(); }
    const f = Math.hypot(dev.force[0], dev.force[1], dev.force[2]);
    if (p.vibrationActuator && f > 0.05 && dev.role === "control")
      p.vibrationActuator.playEffect("dual-rumble", { duration: 40, strongMagnitude: Math.min(1, f / 3.3), weakMagnitude: 0 }).catch(() => {});
    break;
  }
}

frames();
stats();
fetch("/ws" + location.search, { cache: "no-store" }).then((r) => { if (r.status !== 404) { deviceOn = true; setupInput(); setupControls(); connectDevice(); } }).catch(() => {});
let sendTimer = setInterval(send, dev.sendMs);  // the server's hello says the scene's device.browser_send_ms
setInterval(sendLatency, 250);
</script>
</body>
</html>
)PAGE";
  return page;
}

}  // namespace palpate
