// The live view's page: one HTML document with its style and script inline (it fetches nothing but the
// server's own /frame.png and /stats.json).
//
// Frames are long-polled as PNG (/frame.png?after=N answers with the first frame newer than N, or 204 after a
// second): the script knows each frame's index (X-Frame header), draws it on a canvas and asks for the next only
// then, so a slow link or a busy browser gets fewer frames instead of a growing backlog, and every request is
// an ordinary short GET that SSH tunnels and proxies pass unchanged.
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
#view { background: #000; max-width: 100%; height: auto; }
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
  <canvas id="view" width="640" height="480"></canvas>
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

frames();
stats();
</script>
</body>
</html>
)PAGE";
  return page;
}

}  // namespace palpate
