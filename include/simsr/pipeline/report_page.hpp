#pragma once
/// \file
/// The report people open: DIR/report/index.html, static files that work from disk (file://, no
/// server, no network): Table 1 from the JSON report, Fig. 5's frame-wise plot, and a 3D viewer
/// (three.js, vendored from the npm registry at build time) that plays a test performance with a
/// method's prediction beside the truth, the prediction coloured by its per-vertex error,
/// switchable per method.
///
///     pipeline::write_report_page(out / "report", report, viewer_data, vendor_dir);
///
/// Files: index.html (page and viewer code), data.js (`window.SIMSR = {report, faces, rest,
/// sequences}`: a classic script, because file:// pages may not fetch() their neighbours),
/// three.min.js + OrbitControls.js (three r147, the last release with classic builds: module
/// scripts are blocked on file://), frame_errors.svg. Positions travel as int16 displacements from
/// the rest shape, one unit per method and sequence (largest displacement / 32767: 0.3 µm for 2 cm),
/// base64-encoded; the viewer computes the errors from them.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../core/error.hpp"
#include "../core/types.hpp"
#include "../data/frame_set.hpp"
#include "../io/atomic_file.hpp"

namespace simsr::pipeline {

/// What the viewer plays: HR rest surface, and per test sequence some frames of the truth and of
/// every method's prediction (absolute positions).
struct ViewerData {
  Points<Scalar> rest;
  Tris faces;
  struct Sequence {
    std::string name;
    std::vector<std::int64_t> frame_ids;
    data::FrameMatrix<Scalar> truth;                 ///< frames × 3M
    std::vector<std::string> methods;
    std::vector<data::FrameMatrix<Scalar>> predicted;  ///< per method, frames × 3M
  };
  std::vector<Sequence> sequences;
};

namespace detail {

inline std::string base64(const void* data, std::size_t size) {
  static constexpr char table[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const unsigned v = (unsigned(p[i]) << 16) | (unsigned(p[i + 1]) << 8) | p[i + 2];
    out += table[v >> 18], out += table[(v >> 12) & 63], out += table[(v >> 6) & 63], out += table[v & 63];
  }
  if (i < size) {
    const unsigned v = (unsigned(p[i]) << 16) | (i + 1 < size ? unsigned(p[i + 1]) << 8 : 0u);
    out += table[v >> 18], out += table[(v >> 12) & 63];
    out += i + 1 < size ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

/// Displacements of `frames` (F×3M absolute) from `rest` as int16 in units of the returned scale
/// (little-endian, as JavaScript's Int16Array reads it on every platform simsr builds for).
inline nlohmann::json quantized(const data::FrameMatrix<Scalar>& frames, const Points<Scalar>& rest, const std::string& what) {
  const Index m = rest.rows();
  double largest = 0;
  for (Index f = 0; f < frames.rows(); ++f)
    for (Index i = 0; i < 3 * m; ++i) {
      const double d = frames(f, i) - rest(i / 3, i % 3);
      if (!std::isfinite(d)) throw ArgumentError("report page: " + what + ": frame row " + std::to_string(f) + " has a non-finite position");
      largest = std::max(largest, std::abs(d));
    }
  const double unit = largest > 0 ? largest / 32767.0 : 1.0;
  std::vector<std::int16_t> q(std::size_t(frames.rows() * 3 * m));
  for (Index f = 0; f < frames.rows(); ++f)
    for (Index i = 0; i < 3 * m; ++i) q[std::size_t(f * 3 * m + i)] = std::int16_t(std::lround((frames(f, i) - rest(i / 3, i % 3)) / unit));
  return {{"unit", unit}, {"data", base64(q.data(), q.size() * sizeof(std::int16_t))}};
}

/// The page: Table 1 and the viewer, filled from data.js by its own script.
inline const char* report_html() {
  return R"HTML(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>simsr report</title>
<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
td, th { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
#viewer { width: 960px; height: 480px; border: 1px solid #bbb; display: block; }
.controls { margin: 0.5em 0; } .controls > * { margin-right: 1em; }
#notice { color: #a00; }
</style></head><body>
<h1>simsr: super-resolution on <span id="dataset"></span></h1>
<p id="summary"></p>
<h2>Table 1: per-vertex error on the test frames</h2>
<p>Relative to the bounding-box diagonal; the last column normalizes the mean to the largest, as the paper does.</p>
<table id="table1"><thead><tr><th>method</th><th>mean</th><th>median</th><th>std</th><th>max</th><th>min</th><th>mean (normalized)</th></tr></thead><tbody></tbody></table>
<h2>Frame-wise mean error (Fig. 5)</h2>
<img src="frame_errors.svg" alt="frame-wise errors" width="900">
<h2>Prediction (error colours) beside the truth</h2>
<div class="controls">
  <label>performance <select id="sequence"></select></label>
  <label>method <select id="method"></select></label>
  <button id="play">pause</button>
  <label>frame <input id="frame" type="range" min="0" value="0"></label><span id="frame-label"></span>
  <span>colour: 0 (blue) to <span id="scale-label"></span> (red)</span>
</div>
<p id="notice"></p>
<canvas id="viewer" width="960" height="480"></canvas>
<script src="data.js"></script>
<script src="three.min.js" onerror="document.getElementById('notice').textContent = 'three.min.js is missing: the 3D viewer is off (build with npm available).'"></script>
<script src="OrbitControls.js" onerror="void 0"></script>
<script>
(function () {
  const S = window.SIMSR, R = S.report;
  document.getElementById('dataset').textContent = R.dataset;
  document.getElementById('summary').textContent = R.train_frames + ' training frames, ' + R.test_frames + ' test frames' +
    (R.test_sequences ? ' (' + R.test_sequences.join(', ') + ')' : '') + '; bounding-box diagonal ' + R.bbox_diagonal.toPrecision(4) + '.';
  const body = document.querySelector('#table1 tbody');
  for (const name of Object.keys(R.table1)) {
    const m = R.table1[name], tr = document.createElement('tr');
    const cell = (text, stat) => { const td = document.createElement('td'); td.textContent = text; if (stat) td.dataset.stat = stat; tr.appendChild(td); };
    tr.dataset.method = name;
    cell(name);
    for (const s of ['mean', 'median', 'std', 'max', 'min']) cell(m.relative[s].toExponential(4), 'relative_' + s);
    cell(m.normalized.mean.toFixed(4), 'normalized_mean');
    body.appendChild(tr);
  }
  if (typeof THREE === 'undefined' || !S.sequences.length) { document.title = 'simsr report: ready'; return; }
  const bytes = (b64) => { const s = atob(b64), u = new Uint8Array(s.length); for (let i = 0; i < s.length; ++i) u[i] = s.charCodeAt(i); return u.buffer; };
  const decode = (b64) => new Int16Array(bytes(b64));
  const faces = new Uint32Array(bytes(S.faces)), rest = new Float64Array(bytes(S.rest));
  const M = rest.length / 3;
  const canvas = document.getElementById('viewer');
  const renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setScissorTest(true);
  const mesh = (coloured) => {
    const g = new THREE.BufferGeometry();
    g.setIndex(new THREE.BufferAttribute(faces, 1));
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * M), 3));
    if (coloured) g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * M), 3));
    const mat = new THREE.MeshLambertMaterial(coloured ? { vertexColors: true, side: THREE.DoubleSide } : { color: 0xd9c7b8, side: THREE.DoubleSide });
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xffffff);
    scene.add(new THREE.AmbientLight(0xffffff, 0.45));
    const light = new THREE.DirectionalLight(0xffffff, 0.7); light.position.set(0.3, 0.4, 1); scene.add(light);
    const obj = new THREE.Mesh(g, mat); scene.add(obj);
    return { geometry: g, scene: scene };
  };
  const pred = mesh(true), truth = mesh(false);
  let lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < M; ++i) for (let c = 0; c < 3; ++c) { lo[c] = Math.min(lo[c], rest[3 * i + c]); hi[c] = Math.max(hi[c], rest[3 * i + c]); }
  const centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const camera = new THREE.PerspectiveCamera(30, 1, size / 100, size * 100);
  camera.position.set(centre.x + 0.35 * size, centre.y + 0.1 * size, centre.z + 2.2 * size);
  camera.lookAt(centre);
  const controls = THREE.OrbitControls ? new THREE.OrbitControls(camera, canvas) : null;
  if (controls) { controls.target.copy(centre); controls.update(); }
  const seqSel = document.getElementById('sequence'), methSel = document.getElementById('method'), slider = document.getElementById('frame');
  S.sequences.forEach((s, i) => seqSel.add(new Option(s.name, i)));
  let decoded = {}, frame = 0, playing = true, top = 1;
  const arrays = (s, name) => { const key = s + '/' + name; if (!decoded[key]) { const q = name === '__truth' ? S.sequences[s].truth : S.sequences[s].methods[name]; decoded[key] = { q: decode(q.data), unit: q.unit }; } return decoded[key]; };
  const fillMethods = () => {
    const s = S.sequences[+seqSel.value];
    const keep = methSel.value;
    methSel.innerHTML = '';
    for (const name of Object.keys(s.methods)) methSel.add(new Option(name, name));
    if (keep && s.methods[keep]) methSel.value = keep;
    else if (s.methods.network) methSel.value = 'network';
    slider.max = s.frames.length - 1;
    // one colour scale per sequence: Embedded's 99th-percentile error if there, else the first method's
    const ref = s.methods.embedded ? 'embedded' : Object.keys(s.methods)[0];
    const t = arrays(+seqSel.value, '__truth'), r = arrays(+seqSel.value, ref), errs = [];
    for (let f = 0; f < s.frames.length; ++f) for (let i = 0; i < M; i += 7) {
      let d = 0; for (let c = 0; c < 3; ++c) { const k = (f * M + i) * 3 + c, e = r.q[k] * r.unit - t.q[k] * t.unit; d += e * e; }
      errs.push(Math.sqrt(d));
    }
    errs.sort((a, b) => a - b);
    top = errs[Math.floor(0.99 * (errs.length - 1))] || 1e-12;
    document.getElementById('scale-label').textContent = top.toExponential(2);
  };
  const show = () => {
    const s = +seqSel.value, seq = S.sequences[s];
    const t = arrays(s, '__truth'), p = arrays(s, methSel.value);
    const tp = truth.geometry.attributes.position.array, pp = pred.geometry.attributes.position.array, col = pred.geometry.attributes.color.array;
    const base = frame * M * 3;
    for (let i = 0; i < M; ++i) {
      let d = 0;
      for (let c = 0; c < 3; ++c) {
        const k = base + 3 * i + c, x = rest[3 * i + c] + t.q[k] * t.unit, y = rest[3 * i + c] + p.q[k] * p.unit;
        tp[3 * i + c] = x; pp[3 * i + c] = y; d += (x - y) * (x - y);
      }
      const h = Math.min(Math.sqrt(d) / top, 1), colr = new THREE.Color().setHSL(0.667 * (1 - h), 1, 0.5);
      col[3 * i] = colr.r; col[3 * i + 1] = colr.g; col[3 * i + 2] = colr.b;
    }
    for (const m of [truth, pred]) { m.geometry.attributes.position.needsUpdate = true; m.geometry.computeVertexNormals(); }
    pred.geometry.attributes.color.needsUpdate = true;
    slider.value = frame;
    document.getElementById('frame-label').textContent = ' ' + seq.frames[frame] + ' (' + (frame + 1) + '/' + seq.frames.length + ')';
  };
  const draw = () => {
    const w = canvas.width, h = canvas.height;
    camera.aspect = (w / 2) / h; camera.updateProjectionMatrix();
    renderer.setViewport(0, 0, w / 2, h); renderer.setScissor(0, 0, w / 2, h); renderer.render(pred.scene, camera);
    renderer.setViewport(w / 2, 0, w / 2, h); renderer.setScissor(w / 2, 0, w / 2, h); renderer.render(truth.scene, camera);
  };
  seqSel.onchange = () => { frame = 0; fillMethods(); show(); draw(); };
  methSel.onchange = () => { show(); draw(); };
  slider.oninput = () => { frame = +slider.value; show(); draw(); };
  document.getElementById('play').onclick = (e) => { playing = !playing; e.target.textContent = playing ? 'pause' : 'play'; };
  if (controls) controls.addEventListener('change', draw);
  fillMethods(); show(); draw();
  document.title = 'simsr report: ready';
  let last = 0;
  const tick = (t) => {
    if (playing && t - last > 120) { last = t; frame = (frame + 1) % S.sequences[+seqSel.value].frames.length; show(); draw(); }
    requestAnimationFrame(tick);
  };
  requestAnimationFrame(tick);
})();
</script></body></html>
)HTML";
}

}  // namespace detail

/// Writes the page into `dir` (see the file comment). `vendor_dir` holds three's npm package
/// (node_modules/three): its classic builds are copied next to the page; when it is empty or lacks
/// them the page is written without the 3D viewer and the returned note says so. Returns a note
/// for the log ("" when complete).
inline std::string write_report_page(const std::filesystem::path& dir, const nlohmann::ordered_json& report, const ViewerData& v,
                                     const std::filesystem::path& vendor_dir, const std::filesystem::path& frame_errors_svg) {
  std::filesystem::create_directories(dir);
  nlohmann::ordered_json data;
  data["report"] = report;
  std::vector<std::uint32_t> faces(std::size_t(v.faces.size()));
  for (Index f = 0; f < v.faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) faces[std::size_t(3 * f + c)] = std::uint32_t(v.faces(f, c));
  data["faces"] = detail::base64(faces.data(), faces.size() * sizeof(std::uint32_t));
  std::vector<double> rest(std::size_t(v.rest.size()));
  for (Index i = 0; i < v.rest.rows(); ++i)
    for (int c = 0; c < 3; ++c) rest[std::size_t(3 * i + c)] = v.rest(i, c);
  data["rest"] = detail::base64(rest.data(), rest.size() * sizeof(double));
  data["sequences"] = nlohmann::json::array();
  for (const auto& s : v.sequences) {
    if (s.truth.cols() != 3 * v.rest.rows() || Index(s.frame_ids.size()) != s.truth.rows() || s.methods.size() != s.predicted.size())
      throw ShapeError("report page: sequence " + s.name + " (frames, 3M)", {Index(s.frame_ids.size()), 3 * v.rest.rows()}, {s.truth.rows(), s.truth.cols()});
    nlohmann::ordered_json js;
    js["name"] = s.name;
    js["frames"] = s.frame_ids;
    js["truth"] = detail::quantized(s.truth, v.rest, s.name + " truth");
    for (std::size_t k = 0; k < s.methods.size(); ++k) {
      if (s.predicted[k].rows() != s.truth.rows() || s.predicted[k].cols() != s.truth.cols())
        throw ShapeError("report page: " + s.name + ", " + s.methods[k], {s.truth.rows(), s.truth.cols()}, {s.predicted[k].rows(), s.predicted[k].cols()});
      js["methods"][s.methods[k]] = detail::quantized(s.predicted[k], v.rest, s.name + " " + s.methods[k]);
    }
    data["sequences"].push_back(std::move(js));
  }
  io::write_file_atomic(dir / "data.js", "window.SIMSR = " + data.dump() + ";\n");
  io::write_file_atomic(dir / "index.html", detail::report_html());
  const auto copy = [&](const std::filesystem::path& from, const std::string& name) {
    std::ifstream in(from, std::ios::binary);
    if (!in) throw ParseError(from.string(), 0, "cannot read it for the report page");
    std::ostringstream text;
    text << in.rdbuf();
    io::write_file_atomic(dir / name, text.str());
  };
  if (std::filesystem::exists(frame_errors_svg)) copy(frame_errors_svg, "frame_errors.svg");
  const auto three = vendor_dir / "three" / "build" / "three.min.js", orbit = vendor_dir / "three" / "examples" / "js" / "controls" / "OrbitControls.js";
  if (vendor_dir.empty() || !std::filesystem::exists(three) || !std::filesystem::exists(orbit))
    return "the report page has no 3D viewer: three.js (npm package three@0.147.0) was not found in '" + vendor_dir.string() +
           "' (the build vendors it when npm is installed)";
  copy(three, "three.min.js");
  copy(orbit, "OrbitControls.js");
  return "";
}

}  // namespace simsr::pipeline
