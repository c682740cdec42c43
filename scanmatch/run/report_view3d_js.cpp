// The 3D view's script (report_view3d.hpp): reads the JSON of #view3d-data, builds the three.js
// scene and its controls, and writes what it drew to #view3d-status. Plain ES5 over three.js
// r111 (Debian's libjs-three) and its OrbitControls, both inlined before it.

#include "scanmatch/run/report_view3d.hpp"

namespace scanmatch {

const char* const kView3DScript = R"JS(
(function () {
  'use strict';
  var statusEl = document.getElementById('view3d-status');
  var status = {three: true, webgl: false, points: 0, trajectory_vertices: 0, loop_edges: 0,
                flagged_frames: 0, noted_frames: 0, grid: null, errors: window.view3dErrors || []};
  function publish() { statusEl.textContent = JSON.stringify(status); }
  window.view3dPublish = publish;
  function note(text) {
    var p = document.getElementById('view3d-note');
    p.insertBefore(document.createTextNode(text + ' '), p.firstChild);
  }
  var started = performance.now();
  try {
    main();
  } catch (e) {
    status.errors.push(String(e && e.message || e));
    note('The 3D view failed: ' + (e && e.message) + '.');
  }
  publish();

  function bytes(base64) {
    var text = atob(base64), n = text.length, out = new Uint8Array(n);
    for (var i = 0; i < n; ++i) out[i] = text.charCodeAt(i);
    return out;
  }
  // t in [0, 1] to a blue-cyan-green-yellow-red ramp, as bytes at out[k..k+2].
  function ramp(t, out, k) {
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    out[k] = 255 * Math.max(0, Math.min(1, 1.5 - Math.abs(4 * t - 3)));
    out[k + 1] = 255 * Math.max(0, Math.min(1, 1.5 - Math.abs(4 * t - 2)));
    out[k + 2] = 255 * Math.max(0, Math.min(1, 1.5 - Math.abs(4 * t - 1)));
  }
  function quantile(sorted, q) { return sorted[Math.min(sorted.length - 1, Math.floor(q * sorted.length))]; }

  function main() {
    var data = JSON.parse(document.getElementById('view3d-data').textContent);
    var box = document.getElementById('view3d-canvas');
    var bar = document.getElementById('view3d-bar');
    var tip = document.getElementById('view3d-tip');
    // #view3d-only: the view fills the window (screenshots); &view=VIEW starts in VIEW,
    // &color=intensity colours by intensity, &frame=K shows frame K of the first run as a click
    // would (or follows it in the follow view).
    var args = {}, only = false;
    location.hash.slice(1).split('&').forEach(function (token) {
      var pair = token.split('=');
      if (pair.length === 2) args[pair[0]] = decodeURIComponent(pair[1]);
      else if (token === 'view3d-only') only = true;
    });
    if (only) document.body.classList.add('view3d-only');

    var renderer;
    try {
      renderer = new THREE.WebGLRenderer({antialias: false, preserveDrawingBuffer: true});
    } catch (e) {
      note('This browser gives the page no WebGL, so the 3D view is off; the 2D views below ' +
           'show the same runs.');
      return;
    }
    status.webgl = true;
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setClearColor(0x15171c);
    box.appendChild(renderer.domElement);
    var scene = new THREE.Scene();
    var bounds = new THREE.Box3();
    var layers = {};  // name -> objects, for the check boxes
    function addTo(layer, object) {
      (layers[layer] = layers[layer] || []).push(object);
      scene.add(object);
      return object;
    }

    // The map: 16-bit positions relative to its box, scaled back by the object's transform.
    var map = data.map, quantized = null, intensity = null, mapPoints = null;
    if (map && map.count > 0) {
      quantized = new Int16Array(bytes(map.xyz).buffer, 0, map.count * 3);
      var geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(quantized, 3, true));
      geometry.setAttribute('color', new THREE.BufferAttribute(new Uint8Array(map.count * 3), 3, true));
      mapPoints = new THREE.Points(geometry, new THREE.PointsMaterial(
          {size: map.count > 300000 ? 1 : 2, sizeAttenuation: false, vertexColors: THREE.VertexColors}));
      mapPoints.scale.set(map.half[0], map.half[1], map.half[2]);
      mapPoints.position.set(map.center[0], map.center[1], map.center[2]);
      mapPoints.frustumCulled = false;
      addTo('map', mapPoints);
      if (map.intensity) intensity = bytes(map.intensity);
      status.points = map.count;
      // Frame the view on the bulk of the map, not on its farthest stray points.
      var axes = [[], [], []], stride = Math.max(1, Math.floor(map.count / 20000));
      for (var i = 0; i < map.count; i += stride)
        for (var a = 0; a < 3; ++a) axes[a].push(map.center[a] + quantized[3 * i + a] / 32767 * map.half[a]);
      var low = [], high = [];
      for (a = 0; a < 3; ++a) {
        axes[a].sort(function (x, y) { return x - y; });
        low.push(quantile(axes[a], 0.01));
        high.push(quantile(axes[a], 0.99));
      }
      bounds.expandByPoint(new THREE.Vector3(low[0], low[1], low[2]));
      bounds.expandByPoint(new THREE.Vector3(high[0], high[1], high[2]));
    }
    function colorBy(mode) {
      if (!mapPoints) return;
      var colors = mapPoints.geometry.attributes.color.array, n = map.count, k;
      if (mode === 'intensity' && intensity) {
        for (k = 0; k < n; ++k) ramp(intensity[k] / 255, colors, 3 * k);
      } else {
        var sample = [], stride = Math.max(1, Math.floor(n / 20000));
        for (k = 0; k < n; k += stride) sample.push(quantized[3 * k + 2]);
        sample.sort(function (x, y) { return x - y; });
        var lo = quantile(sample, 0.02), hi = Math.max(lo + 1, quantile(sample, 0.98));
        for (k = 0; k < n; ++k) ramp((quantized[3 * k + 2] - lo) / (hi - lo), colors, 3 * k);
      }
      mapPoints.geometry.attributes.color.needsUpdate = true;
    }
    colorBy('height');

    // A map2d run's occupancy grid: a textured plane under the trajectories.
    var grid = data.grid;
    if (grid) {
      var texture = new THREE.DataTexture(bytes(grid.pixels), grid.width, grid.height,
                                          THREE.LuminanceFormat, THREE.UnsignedByteType);
      texture.unpackAlignment = 1;
      texture.magFilter = THREE.NearestFilter;
      texture.minFilter = THREE.LinearFilter;
      texture.generateMipmaps = false;
      texture.needsUpdate = true;
      var w = grid.width * grid.cell, h = grid.height * grid.cell;
      var plane = new THREE.Mesh(new THREE.PlaneBufferGeometry(w, h),
                                 new THREE.MeshBasicMaterial({map: texture, side: THREE.DoubleSide}));
      plane.position.set(grid.origin[0] + w / 2, grid.origin[1] + h / 2, -0.05);
      addTo('grid', plane);
      status.grid = grid.width + 'x' + grid.height;
    }

    // Trajectories, loop edges and flagged frames, drawn over the map (no depth test): the
    // path must show where the points hide it.
    var pathBounds = new THREE.Box3();
    function line(layer, xyz, color, opacity, segments) {
      var geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(xyz, 3));
      var material = new THREE.LineBasicMaterial(
          {color: color, transparent: opacity < 1, opacity: opacity, depthTest: false});
      var object = segments ? new THREE.LineSegments(geometry, material) : new THREE.Line(geometry, material);
      object.renderOrder = 2;
      for (var k = 0; k + 2 < xyz.length; k += 3) {
        bounds.expandByPoint(new THREE.Vector3(xyz[k], xyz[k + 1], xyz[k + 2]));
        pathBounds.expandByPoint(new THREE.Vector3(xyz[k], xyz[k + 1], xyz[k + 2]));
      }
      return addTo(layer, object);
    }
    function markers(layer, xyz, color, size) {
      var geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(xyz, 3));
      var object = new THREE.Points(geometry, new THREE.PointsMaterial(
          {color: color, size: size, sizeAttenuation: false, depthTest: false}));
      object.renderOrder = 3;
      return addTo(layer, object);
    }
    var legend = [];
    function legendEntry(color, text) {
      legend.push('<span style="color:' + color + '">&#9644;</span> ' +
                  text.replace(/&/g, '&amp;').replace(/</g, '&lt;'));
    }
    var referenceColor = grid ? '#1060ff' : '#f2f2f2';
    if (data.reference) {
      line('reference', data.reference, referenceColor, 1, false);
      status.trajectory_vertices += data.reference.length / 3;
      legendEntry(referenceColor, 'reference');
    }
    var picks = [];  // per run: the positions hover and click look at
    data.runs.forEach(function (run) {
      var main = run.optimized || run.odometry;
      line('odometry', run.odometry, run.color, run.optimized ? 0.5 : 1, false);
      status.trajectory_vertices += run.odometry.length / 3;
      legendEntry(run.color, run.label + ' (' + run.method + ')' + (run.optimized ? ', odometry faded' : ''));
      // The poses as dots too: a one-pixel line alone is lost among the map's points.
      markers(run.optimized ? 'loop-closed' : 'odometry', main, run.color, 4);
      if (run.optimized) {
        line('loop-closed', run.optimized, run.color, 1, false);
        status.trajectory_vertices += run.optimized.length / 3;
        legendEntry(run.color, run.label + ' loop-closed');
      }
      if (run.loops.length) {
        var edges = [];
        run.loops.forEach(function (edge) {
          for (var e = 0; e < 2; ++e)
            edges.push(main[3 * edge[e]], main[3 * edge[e] + 1], main[3 * edge[e] + 2]);
        });
        line('loop edges', edges, '#3ddc4a', 1, true);
        status.loop_edges += run.loops.length;
      }
      var at = function (frames) {
        var xyz = [];
        frames.forEach(function (k) { xyz.push(main[3 * k], main[3 * k + 1], main[3 * k + 2]); });
        return xyz;
      };
      if (run.noted.length) markers('uncertain prior', at(run.noted), '#ffa020', 5).visible = false;
      if (run.marked.length) markers('flagged frames', at(run.marked), '#ff3030', 8);
      status.flagged_frames += run.marked.length;
      status.noted_frames += run.noted.length;
      picks.push({run: run, xyz: main});
    });
    if (status.loop_edges) legendEntry('#3ddc4a', 'loop edges (' + status.loop_edges + ')');
    if (status.flagged_frames)
      legendEntry('#ff3030', 'flagged frames: bridged, thin map or stages disagree (' + status.flagged_frames + ')');
    if (status.noted_frames)
      legendEntry('#ffa020', 'uncertain prior or recovered only (' + status.noted_frames + ', layer off)');
    document.getElementById('view3d-legend').innerHTML = legend.join('<br>');
    var highlight = markers('picked', [0, 0, 0], '#ffffff', 12);
    highlight.visible = false;

    // Camera and controls: z is up.
    if (bounds.isEmpty()) bounds.expandByPoint(new THREE.Vector3(0, 0, 0));
    var center = bounds.getCenter(new THREE.Vector3()), extent = bounds.getSize(new THREE.Vector3());
    var radius = Math.max(extent.length() / 2, 1);
    var camera = new THREE.PerspectiveCamera(50, 1, radius / 2000, radius * 40);
    camera.up.set(0, 0, 1);
    var controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.screenSpacePanning = true;
    controls.addEventListener('change', render);
    // One frame at a time, on demand, and none while the page sets up: in software (SwiftShader)
    // a frame of a million points takes a good part of a second.
    var ready = false, frameRequested = false;
    function render() {
      if (!ready || frameRequested) return;
      frameRequested = true;
      requestAnimationFrame(function () {
        frameRequested = false;
        renderer.render(scene, camera);
      });
    }
    function resize() {
      if (only) box.style.height = (window.innerHeight - bar.offsetHeight) + 'px';
      renderer.setSize(box.clientWidth, box.clientHeight);
      camera.aspect = box.clientWidth / Math.max(1, box.clientHeight);
      camera.updateProjectionMatrix();
      render();
    }
    // Distance at which a w x h extent seen square-on fills the view.
    function fit(w, h) {
      var t = Math.tan(camera.fov / 2 * Math.PI / 180);
      return 1.08 * Math.max(h / 2 / t, w / 2 / (t * camera.aspect));
    }
    var frames = picks.length ? picks[0].xyz.length / 3 : 0, following = false;
    function view(name) {
      following = name === 'follow';
      slider.disabled = !following;
      controls.target.copy(center);
      if (name === 'top') {
        camera.position.set(center.x, center.y - 1e-3 * radius, bounds.max.z + fit(extent.x, extent.y));
      } else if (name === 'side') {
        camera.position.set(center.x, bounds.min.y - fit(extent.x, extent.z), center.z);
      } else if (name === 'follow') {
        followFrame(Number(slider.value));
        return;
      } else if (name === 'path' && !pathBounds.isEmpty()) {
        // Oblique, framing the trajectories with a margin rather than the whole map.
        var c = pathBounds.getCenter(new THREE.Vector3()), e = pathBounds.getSize(new THREE.Vector3());
        var reach = fit(Math.max(e.x, 10) * 1.3, Math.max(e.y, 10) * 1.3);
        controls.target.copy(c);
        camera.position.set(c.x - 0.35 * reach, c.y - 0.75 * reach, c.z + 0.75 * reach);
      } else {
        var d = fit(extent.x, extent.y);
        camera.position.set(center.x - 0.35 * d, center.y - 0.75 * d, center.z + 0.75 * d);
      }
      controls.update();
    }
    // Behind and above frame k, looking along its heading.
    function followFrame(k) {
      if (!frames) return;
      var p = picks[0].xyz, yaw = picks[0].run.yaw[k] || 0, back = Math.min(30, Math.max(6, radius * 0.06));
      var at = new THREE.Vector3(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
      camera.position.set(at.x - back * Math.cos(yaw), at.y - back * Math.sin(yaw), at.z + 0.45 * back);
      controls.target.set(at.x + back * Math.cos(yaw), at.y + back * Math.sin(yaw), at.z);
      controls.update();
      showFrame({pick: picks[0], k: k}, null);
    }

    // The tool bar.
    function button(text, onclick) {
      var b = document.createElement('button');
      b.textContent = text;
      b.onclick = onclick;
      bar.appendChild(b);
      return b;
    }
    function label(text) {
      var s = document.createElement('span');
      s.textContent = text;
      bar.appendChild(s);
      return s;
    }
    label('View:');
    button('Top', function () { view('top'); });
    button('Side', function () { view('side'); });
    button('Oblique', function () { view('oblique'); });
    button('Path', function () { view('path'); });
    button('Follow', function () { view('follow'); });
    var slider = document.createElement('input');
    slider.type = 'range';
    slider.min = 0;
    slider.max = Math.max(0, frames - 1);
    slider.value = 0;
    slider.title = 'frame to follow';
    slider.oninput = function () { if (following) followFrame(Number(slider.value)); };
    bar.appendChild(slider);
    var playing = null;
    var play = button('Play', function () {
      if (playing) { clearInterval(playing); playing = null; play.textContent = 'Play'; return; }
      if (!following) view('follow');
      play.textContent = 'Stop';
      playing = setInterval(function () {
        var k = Number(slider.value) + 1;
        if (k >= frames) { clearInterval(playing); playing = null; play.textContent = 'Play'; return; }
        slider.value = k;
        followFrame(k);
      }, 50);
    });
    if (mapPoints) {
      label('Colour:');
      var modes = document.createElement('select');
      modes.innerHTML = '<option value="height">height</option>' +
                        (intensity ? '<option value="intensity">intensity</option>' : '');
      modes.onchange = function () { colorBy(modes.value); render(); };
      bar.appendChild(modes);
      label('Point size:');
      var size = document.createElement('input');
      size.type = 'range';
      size.min = 1;
      size.max = 6;
      size.value = mapPoints.material.size;
      size.oninput = function () { mapPoints.material.size = Number(size.value); render(); };
      bar.appendChild(size);
    }
    Object.keys(layers).forEach(function (name) {
      if (name === 'picked') return;
      var l = document.createElement('label'), check = document.createElement('input');
      check.type = 'checkbox';
      check.checked = layers[name][0].visible;
      check.onchange = function () {
        layers[name].forEach(function (o) { o.visible = check.checked; });
        render();
      };
      l.appendChild(check);
      l.appendChild(document.createTextNode(name));
      bar.appendChild(l);
    });

    // Hover and click: the frame nearest the pointer within 10 pixels, of any run.
    function pick(event) {
      var rect = renderer.domElement.getBoundingClientRect(), x = event.clientX - rect.left,
          y = event.clientY - rect.top, best = null, bestDistance = 100, v = new THREE.Vector3();
      picks.forEach(function (pick) {
        for (var k = 0; 3 * k < pick.xyz.length; ++k) {
          v.set(pick.xyz[3 * k], pick.xyz[3 * k + 1], pick.xyz[3 * k + 2]).project(camera);
          if (v.z > 1 || v.z < -1) continue;
          var dx = (v.x + 1) / 2 * rect.width - x, dy = (1 - v.y) / 2 * rect.height - y;
          if (dx * dx + dy * dy < bestDistance) { bestDistance = dx * dx + dy * dy; best = {pick: pick, k: k}; }
        }
      });
      return best;
    }
    function showFrame(hit, event) {
      if (!hit) { tip.style.display = 'none'; highlight.visible = false; render(); return; }
      var run = hit.pick.run, k = hit.k, m = run.step_m[k], deg = run.step_deg[k];
      tip.textContent = run.label + ' (' + run.method + '), frame ' + k + '\nstep error: ' +
          (m === null || m === undefined ? 'no reference' : m.toFixed(3) + ' m, ' + deg.toFixed(2) + ' deg') +
          '\nhealth: ' + (run.flags[k] || 'healthy');
      tip.style.display = 'block';
      var rect = renderer.domElement.getBoundingClientRect();
      tip.style.left = (event ? event.clientX - rect.left + 14 : 10) + 'px';
      tip.style.top = (event ? event.clientY - rect.top + 14 : 10) + 'px';
      highlight.geometry.attributes.position.setXYZ(0, hit.pick.xyz[3 * k], hit.pick.xyz[3 * k + 1], hit.pick.xyz[3 * k + 2]);
      highlight.geometry.attributes.position.needsUpdate = true;
      highlight.visible = true;
      render();
    }
    var pinned = false;
    renderer.domElement.addEventListener('mousemove', function (event) {
      if (!pinned && !event.buttons) showFrame(pick(event), event);
    });
    renderer.domElement.addEventListener('click', function (event) {
      var hit = pick(event);
      pinned = !!hit;
      showFrame(hit, event);
      if (hit && hit.pick === picks[0]) slider.value = hit.k;
    });

    window.addEventListener('resize', resize);
    resize();
    if (args.color === 'intensity' && intensity) {
      modes.value = 'intensity';
      colorBy('intensity');
    }
    var frame = Number(args.frame);
    if (args.frame !== undefined && frame >= 0 && frame < frames) slider.value = frame;
    view(args.view || (grid && !mapPoints ? 'top' : 'path'));
    if (args.frame !== undefined && frame >= 0 && frame < frames && !following)
      showFrame({pick: picks[0], k: frame}, null);
    status.color = mapPoints ? (modes.value) : null;
    ready = true;
    renderer.render(scene, camera);
    // Times for the benchmark: the page up to this script, and this script (decoding, building
    // the scene, the first frame).
    renderer.getContext().finish();
    status.page_ms = Math.round(started);
    status.view_ms = Math.round(performance.now() - started);
    // And when the browser has shown a frame with it: the second animation frame after it.
    requestAnimationFrame(function () {
      requestAnimationFrame(function () {
        status.shown_ms = Math.round(performance.now());
        publish();
      });
    });
    window.view3d = {scene: scene, camera: camera, controls: controls, view: view, render: render};
  }
})();
)JS";

}  // namespace scanmatch
