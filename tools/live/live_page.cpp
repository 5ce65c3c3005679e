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
#include "tools/live/live_server.h"

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
  drag: move the tool &middot; wheel: depth &middot; Space, right button or a long press: button (grab / blade)</div></div>
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
  if (!live.connected && live.stats) { el.textContent = "server stopped (last frame kept)"; el.className = "gone"; }
  else if (!live.connected) { el.textContent = "connecting"; el.className = ""; }
  else if (live.finished) { el.textContent = "finished"; el.className = "finished"; }
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
const dev = { role: "none", x: 0, y: 0, depth: 0, button: false, seq: 0, force: [0, 0, 0], fv: [0, 0, 0],
              hv: [0, 0, 0], scale: 0, sent: 0, feedback: 0, inputAt: 0, pending: [], frameWait: [],
              forceMs: -1, frameMs: -1 };
live.device = dev;
let sock = null, lastEventSeq = 0;
function clamp(v) { return Math.max(-1, Math.min(1, v)); }
// an input event changed the pose: the next message carries it, and its time is kept for the latency figures
function moved() { dev.inputAt = performance.now(); }
function frameDrawn(index) {
  const now = performance.now();
  while (dev.frameWait.length && dev.frameWait[0].k < index) { dev.frameMs = now - dev.frameWait.shift().t; }
}
function connectDevice() {
  sock = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
  sock.onmessage = (e) => {
    const m = JSON.parse(e.data);
    if (m.t === "hello") {
      dev.role = m.role; dev.seq = 0;
      $("device").style.display = "block";
      $("role").textContent = m.role === "control" ? "you steer it" : "watching (another page steers)";
      $("role").className = m.role;
      return;
    }
    dev.force = m.f; dev.fv = m.fv; dev.hv = m.hv; dev.scale = m.scale; dev.feedback++;
    // the first feedback that used a message carrying an input event: event to force computed and back
    const now = performance.now();
    while (dev.pending.length && dev.pending[0].seq <= m.s) {
      const p = dev.pending.shift();
      if (dev.role === "control") { dev.forceMs = now - p.t; dev.frameWait.push({ k: m.k, t: p.t }); }
    }
    if (dev.frameWait.length > 120) dev.frameWait.splice(0, dev.frameWait.length - 120);
    drawForce();
  };
  sock.onclose = () => { dev.role = "none"; $("role").textContent = "not connected"; $("role").className = ""; };
}
function send() {
  pollGamepad();
  if (!sock || sock.readyState !== 1 || dev.role !== "control") return;
  dev.seq++;
  const b = dev.button ? 1 : 0;
  sock.send("p " + dev.seq + " " + dev.x.toFixed(4) + " " + dev.y.toFixed(4) + " " + dev.depth.toFixed(4) + " " + b);
  dev.sent++;
  if (dev.inputAt > 0) { dev.pending.push({ seq: dev.seq, t: dev.inputAt }); dev.inputAt = 0; }
  if (dev.pending.length > 120) dev.pending.splice(0, dev.pending.length - 120);
}
function sendLatency() {
  if (sock && sock.readyState === 1 && dev.role === "control" && (dev.forceMs >= 0 || dev.frameMs >= 0))
    sock.send("l " + Math.min(dev.forceMs, 60000).toFixed(2) + " " + Math.min(dev.frameMs, 60000).toFixed(2));
}
function drawForce() {
  const o = $("overlay"), v = $("view");
  if (o.width !== v.clientWidth || o.height !== v.clientHeight) { o.width = v.clientWidth; o.height = v.clientHeight; }
  const g = o.getContext("2d");
  g.clearRect(0, 0, o.width, o.height);
  if (dev.role === "none") return;
  const px = (dev.hv[0] + 1) / 2 * o.width, py = (1 - dev.hv[1]) / 2 * o.height;
  const f = Math.hypot(dev.force[0], dev.force[1], dev.force[2]), s = 40;  // px per N
  g.strokeStyle = "#ff9800"; g.fillStyle = "#ff9800"; g.lineWidth = 3;
  g.beginPath(); g.arc(px, py, 5, 0, 2 * Math.PI); g.stroke();
  const ex = px + dev.fv[0] * s, ey = py - dev.fv[1] * s;
  g.beginPath(); g.moveTo(px, py); g.lineTo(ex, ey); g.stroke();
  const a = Math.atan2(ey - py, ex - px);
  if (f > 0.01) { g.beginPath(); g.moveTo(ex, ey); g.lineTo(ex - 9 * Math.cos(a - 0.4), ey - 9 * Math.sin(a - 0.4));
                  g.lineTo(ex - 9 * Math.cos(a + 0.4), ey - 9 * Math.sin(a + 0.4)); g.fill(); }
  g.font = "13px system-ui, sans-serif";
  g.fillText("F " + f.toFixed(2) + " N" + (dev.button ? "  [button]" : "") + (dev.scale < 1 ? "  fading " + dev.scale.toFixed(2) : ""), 8, 18);
  $("devinfo").textContent = "force " + f.toFixed(2) + " N, input \u2192 force back " +
      (dev.forceMs >= 0 ? dev.forceMs.toFixed(1) + " ms" : "\u2013") + ", input \u2192 frame " +
      (dev.frameMs >= 0 ? dev.frameMs.toFixed(0) + " ms" : "\u2013");
}
// pointer (mouse, touch, pen): a drag moves the tool; a press held still 0.5 s (or the right button) is the button
let dragging = false, pressTimer = 0, pressAt = null;
function at(e) {
  const r = $("overlay").getBoundingClientRect();
  dev.x = clamp((e.clientX - r.left) / r.width * 2 - 1);
  dev.y = clamp(1 - (e.clientY - r.top) / r.height * 2);
  if (e.pointerType === "pen" && e.pressure > 0) dev.depth = clamp(e.pressure * 2 - 1);
  moved();
}
function setupInput() {
  const o = $("overlay");
  o.addEventListener("contextmenu", (e) => e.preventDefault());
  o.addEventListener("pointerdown", (e) => {
    o.setPointerCapture(e.pointerId);
    dragging = true; at(e);
    if (e.button === 2) { dev.button = true; moved(); return; }
    pressAt = [e.clientX, e.clientY];
    clearTimeout(pressTimer);
    pressTimer = setTimeout(() => { dev.button = true; moved(); }, 500);
  });
  o.addEventListener("pointermove", (e) => {
    if (!dragging) return;
    at(e);
    if (pressAt && Math.hypot(e.clientX - pressAt[0], e.clientY - pressAt[1]) > 6) { clearTimeout(pressTimer); pressAt = null; }
  });
  const up = () => { dragging = false; clearTimeout(pressTimer); pressAt = null;
                     if (!keyDown) { dev.button = false; moved(); } };
  o.addEventListener("pointerup", up);
  o.addEventListener("pointercancel", up);
  o.addEventListener("wheel", (e) => { e.preventDefault(); dev.depth = clamp(dev.depth + e.deltaY * 0.001); moved(); },
                     { passive: false });
  window.addEventListener("keydown", (e) => { if (e.code === "Space") { e.preventDefault(); keyDown = true; dev.button = true; moved(); } });
  window.addEventListener("keyup", (e) => { if (e.code === "Space") { keyDown = false; dev.button = false; moved(); } });
}
let keyDown = false, padButton = false;
// gamepad: left stick moves across the view, right stick up/down and the triggers set depth, A or RB is the button;
// the vibration follows the force
function pollGamepad() {
  const pads = navigator.getGamepads ? navigator.getGamepads() : [];
  for (const p of pads) {
    if (!p || !p.connected) continue;
    const dz = (v) => Math.abs(v) < 0.12 ? 0 : v, k = 0.02;
    const lx = dz(p.axes[0] || 0), ly = dz(p.axes[1] || 0), ry = dz(p.axes[3] || 0);
    const lt = p.buttons[6] ? p.buttons[6].value : 0, rt = p.buttons[7] ? p.buttons[7].value : 0;
    if (lx || ly || ry || lt || rt) {
      dev.x = clamp(dev.x + k * lx); dev.y = clamp(dev.y - k * ly);
      dev.depth = clamp(dev.depth + k * (ry + rt - lt)); moved();
    }
    const b = !!((p.buttons[0] && p.buttons[0].pressed) || (p.buttons[5] && p.buttons[5].pressed));
    if (b !== padButton) { padButton = b; dev.button = b; moved(); }
    const f = Math.hypot(dev.force[0], dev.force[1], dev.force[2]);
    if (p.vibrationActuator && f > 0.05 && dev.role === "control")
      p.vibrationActuator.playEffect("dual-rumble", { duration: 40, strongMagnitude: Math.min(1, f / 3.3), weakMagnitude: 0 }).catch(() => {});
    break;
  }
}

frames();
stats();
fetch("/ws", { cache: "no-store" }).then((r) => { if (r.status !== 404) { setupInput(); connectDevice(); } }).catch(() => {});
setInterval(send, 15);
setInterval(sendLatency, 250);
</script>
</body>
</html>
)PAGE";
  return page;
}

}  // namespace palpate
