// trajroi view's page: draws what trajroid publishes, as `trajroi view` forwards it over a
// WebSocket (/ws). Frames (view/include/trajroi/view/frames.hpp): "TRV1", uint32 kind, uint32
// JSON header length, the JSON header, then the kind's arrays (little-endian, 4-byte aligned).
// Drawn: the kept points of the newest sweep (coloured by height, intensity or sensor), the decoded
// points before the ROI in grey (outputs.raw_points), the ROI chain placed for that sweep, the
// active trajectory and the robot. The page writes what it drew in #counters, and tells the
// server each sweep it drew ("drawn <index>") for the latency figures.
'use strict';
(function () {
  var KIND = { sweep: 1, raw: 2, trajectory: 3, status: 4, pose: 5 };
  var MAGIC = 0x31565254;

  // ---- the scene
  var canvas = document.getElementById('scene');
  var renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0x101418);
  var scene = new THREE.Scene();
  var camera = new THREE.PerspectiveCamera(50, 1, 0.1, 5000);
  camera.up.set(0, 0, 1);  // the global frame is ENU: z up
  var controls = new THREE.OrbitControls(camera, canvas);
  controls.screenSpacePanning = true;
  controls.maxPolarAngle = Math.PI / 2;
  function topDown(height) {
    // Straight down, north up on the screen.
    camera.position.set(controls.target.x, controls.target.y - 0.001, controls.target.z + height);
    controls.update();
  }
  topDown(70);

  function resize() {
    var w = window.innerWidth, h = window.innerHeight;
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(1, h);
    camera.updateProjectionMatrix();
    dirty = true;
  }
  window.addEventListener('resize', resize);

  // A cloud whose arrays grow as needed and are otherwise reused.
  function Cloud(size, fixedColour) {
    this.capacity = 0;
    this.geometry = new THREE.BufferGeometry();
    var material = fixedColour === undefined
      ? new THREE.PointsMaterial({ size: size, sizeAttenuation: false, vertexColors: THREE.VertexColors })
      : new THREE.PointsMaterial({ size: size, sizeAttenuation: false, color: fixedColour });
    this.points = new THREE.Points(this.geometry, material);
    this.points.frustumCulled = false;
    this.coloured = fixedColour === undefined;
    this.grow(1024);
    this.geometry.setDrawRange(0, 0);
    scene.add(this.points);
  }
  Cloud.prototype.grow = function (n) {
    this.capacity = Math.max(n, Math.ceil(this.capacity * 1.5));
    var position = new THREE.BufferAttribute(new Float32Array(3 * this.capacity), 3);
    position.setUsage ? position.setUsage(THREE.DynamicDrawUsage) : position.setDynamic(true);
    this.geometry.setAttribute ? this.geometry.setAttribute('position', position)
                               : this.geometry.addAttribute('position', position);
    if (this.coloured) {
      var colour = new THREE.BufferAttribute(new Uint8Array(3 * this.capacity), 3, true);
      colour.setUsage ? colour.setUsage(THREE.DynamicDrawUsage) : colour.setDynamic(true);
      this.geometry.setAttribute ? this.geometry.setAttribute('color', colour)
                                 : this.geometry.addAttribute('color', colour);
    }
  };
  // xyz: Float32Array of 3n; colours: Uint8Array of 3n or null.
  Cloud.prototype.set = function (xyz, colours) {
    var n = xyz.length / 3;
    if (n > this.capacity) this.grow(n);
    var position = this.geometry.getAttribute('position');
    position.array.set(xyz);
    position.updateRange.offset = 0;
    position.updateRange.count = 3 * n;
    position.needsUpdate = true;
    if (colours) {
      var colour = this.geometry.getAttribute('color');
      colour.array.set(colours);
      colour.updateRange.offset = 0;
      colour.updateRange.count = 3 * n;
      colour.needsUpdate = true;
    }
    this.geometry.setDrawRange(0, n);
  };
  Cloud.prototype.drawn = function () { return this.geometry.drawRange.count; };

  var raw = new Cloud(1.5, 0x7d8590);
  var kept = new Cloud(2.5);
  kept.points.renderOrder = 1;

  var roiLines = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xffd84d }));
  roiLines.frustumCulled = false;
  scene.add(roiLines);
  var trajectoryLine = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x4dd2ff }));
  trajectoryLine.frustumCulled = false;
  scene.add(trajectoryLine);
  var robot = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(0, 0, 0), 4, 0xff4df0, 1.4, 1.0);
  robot.visible = false;
  scene.add(robot);
  var grid = new THREE.GridHelper(400, 40, 0x2c3540, 0x1c232b);
  grid.rotation.x = Math.PI / 2;  // in the x-y plane
  scene.add(grid);

  // ---- colours: a 256-entry map (blue → cyan → green → yellow → red)
  var lut = new Uint8Array(256 * 3);
  (function () {
    var stops = [[0, 40, 80, 255], [0.25, 0, 200, 255], [0.5, 40, 220, 90], [0.75, 255, 220, 40], [1, 255, 60, 40]];
    for (var i = 0; i < 256; ++i) {
      var t = i / 255, k = 0;
      while (k < stops.length - 2 && t > stops[k + 1][0]) ++k;
      var a = stops[k], b = stops[k + 1], u = (t - a[0]) / (b[0] - a[0]);
      for (var c = 0; c < 3; ++c) lut[3 * i + c] = Math.round(a[c + 1] + u * (b[c + 1] - a[c + 1]));
    }
  })();
  // Several LiDARs: one colour each, in lidars: order (none of the ROI chain's, the trajectory's,
  // the robot's or the raw points').
  var SENSOR_COLOURS = [[255, 140, 40], [110, 255, 110], [170, 120, 255], [255, 255, 255], [255, 90, 90],
                        [90, 140, 255], [200, 200, 90], [255, 170, 200]];
  window.trajroiSensorColours = SENSOR_COLOURS;
  var colourBy = 'height';
  var colourScratch = new Uint8Array(0);
  function colours(xyz, intensity, groundZ, sensor) {
    var n = intensity.length;
    if (colourScratch.length < 3 * n) colourScratch = new Uint8Array(3 * n);
    var out = colourScratch, i, k;
    if (colourBy === 'sensor') {
      for (i = 0; i < n; ++i) {
        var c = SENSOR_COLOURS[sensor[i] % SENSOR_COLOURS.length];
        out[3 * i] = c[0]; out[3 * i + 1] = c[1]; out[3 * i + 2] = c[2];
      }
    } else if (colourBy === 'height') {
      var lo = groundZ - 2.0, scale = 255 / 5.0;  // 5 m of height over the map
      for (i = 0; i < n; ++i) {
        k = Math.max(0, Math.min(255, Math.round((xyz[3 * i + 2] - lo) * scale))) * 3;
        out[3 * i] = lut[k]; out[3 * i + 1] = lut[k + 1]; out[3 * i + 2] = lut[k + 2];
      }
    } else {
      // VLP-16 calibrated reflectivity: 0–100 diffuse, 101–255 retro-reflectors.
      for (i = 0; i < n; ++i) {
        k = Math.min(255, Math.round(intensity[i] * 2.55)) * 3;
        out[3 * i] = lut[k]; out[3 * i + 1] = lut[k + 1]; out[3 * i + 2] = lut[k + 2];
      }
    }
    return out.subarray(0, 3 * n);
  }

  // ---- the page's own record of what it drew
  var stats = { sweepsReceived: 0, sweepsDrawn: 0, framesDrawn: 0, lastSweep: null, pointsDrawn: 0, roiShapes: 0,
                rawDrawn: 0, trajectoryId: null, drawnPerSecond: 0 };
  window.trajroiStats = stats;
  // Where `count` of the drawn kept points are on the screen (CSS pixels), spread over the
  // sweep: for checking a screenshot.
  window.trajroiProject = function (count) {
    var position = kept.geometry.getAttribute('position'), n = kept.drawn(), out = [];
    var v = new THREE.Vector3(), w = canvas.clientWidth, h = canvas.clientHeight;
    for (var k = 0; k < count && n > 0; ++k) {
      var i = Math.floor(k * n / count);
      v.set(position.array[3 * i], position.array[3 * i + 1], position.array[3 * i + 2]).project(camera);
      out.push([(v.x + 1) / 2 * w, (1 - v.y) / 2 * h, lastIntensity ? lastIntensity.sensor[i] : 0]);
    }
    return out;
  };
  var dirty = true, drewSweep = null, lastSweep = null, lastIntensity = null, robotZ = 0;
  var robotAt = null;

  var RTK = ['none', 'float', 'fixed'];
  var PPS = ['absent', 'synchronizing', 'locked', 'error'];
  function setText(id, text) { document.getElementById(id).textContent = text; }
  function fixed(v, digits) { return v === null || v === undefined ? '–' : Number(v).toFixed(digits); }

  function showCounters() {
    setText('counters', 'sweeps received ' + stats.sweepsReceived + ' · sweep ' +
            (stats.lastSweep === null ? '–' : stats.lastSweep) + ' · points ' + stats.pointsDrawn +
            ' · ROIs ' + stats.roiShapes);
  }

  function drawRoi(roi, z) {
    var positions = [], shapes = 0;
    if (roi) {
      var segments = 48;
      roi.centres.forEach(function (c) {
        var cx = c[0], cy = c[1], th = c[2], i;
        if (roi.shape === 'circular') {
          for (i = 0; i < segments; ++i) {
            var a0 = 2 * Math.PI * i / segments, a1 = 2 * Math.PI * (i + 1) / segments;
            positions.push(cx + roi.r * Math.cos(a0), cy + roi.r * Math.sin(a0), z,
                           cx + roi.r * Math.cos(a1), cy + roi.r * Math.sin(a1), z);
          }
        } else {
          // a along the tangent (heading th), b across.
          var ca = Math.cos(th), sa = Math.sin(th), ha = roi.a / 2, hb = roi.b / 2;
          var corners = [[ha, hb], [-ha, hb], [-ha, -hb], [ha, -hb]].map(function (p) {
            return [cx + p[0] * ca - p[1] * sa, cy + p[0] * sa + p[1] * ca];
          });
          for (i = 0; i < 4; ++i) {
            var p = corners[i], q = corners[(i + 1) % 4];
            positions.push(p[0], p[1], z, q[0], q[1], z);
          }
        }
        ++shapes;
      });
    }
    // Written into the attribute in place (grown when a longer chain comes): a new buffer per
    // sweep would leave the GPU one buffer more to free ten times a second.
    var g = roiLines.geometry, attribute = g.getAttribute('position');
    if (!attribute || attribute.array.length < positions.length) {
      attribute = new THREE.BufferAttribute(new Float32Array(Math.max(positions.length, 3 * 4096)), 3);
      attribute.setUsage ? attribute.setUsage(THREE.DynamicDrawUsage) : attribute.setDynamic(true);
      g.setAttribute ? g.setAttribute('position', attribute) : g.addAttribute('position', attribute);
    }
    attribute.array.set(positions);
    attribute.updateRange.offset = 0;
    attribute.updateRange.count = positions.length;
    attribute.needsUpdate = true;
    g.setDrawRange(0, positions.length / 3);
    return shapes;
  }

  // The sensors' names beside their colours (several LiDARs), as the newest sweep gives them.
  var sensorsShown = '';
  function showSensors(names) {
    var text = names.join(',');
    if (text === sensorsShown) return;
    sensorsShown = text;
    var box = document.getElementById('sensors');
    box.textContent = '';
    names.forEach(function (name, i) {
      var c = SENSOR_COLOURS[i % SENSOR_COLOURS.length], swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = 'rgb(' + c.join(',') + ')';
      box.appendChild(swatch);
      box.appendChild(document.createTextNode(name + ' '));
    });
    document.getElementById('colour-sensor').disabled = names.length < 2;
  }

  function onSweep(header, xyz, intensity, sensor) {
    ++stats.sweepsReceived;
    var pose = header.pose;
    if (pose && pose.valid) {
      robotZ = pose.z;
      var at = new THREE.Vector3(pose.x, pose.y, pose.z);
      if (document.getElementById('follow').checked && robotAt) {
        var d = at.clone().sub(robotAt);
        camera.position.add(d);
        controls.target.add(d);
        controls.update();
      } else if (!robotAt) {
        controls.target.copy(at);
        topDown(70);
      }
      robotAt = at;
      robot.position.copy(at);
      robot.setDirection(new THREE.Vector3(Math.cos(pose.yaw), Math.sin(pose.yaw), 0));
      robot.visible = true;
    }
    lastSweep = header;
    lastIntensity = { xyz: xyz, intensity: intensity, sensor: sensor };
    var counts = (header.sensors || []).map(function () { return 0; });
    for (var i = 0; i < sensor.length; ++i) if (sensor[i] < counts.length) ++counts[sensor[i]];
    stats.sensorCounts = counts;  // the shown sweep's points of each sensor
    showSensors(header.sensors || []);
    kept.set(xyz, colours(xyz, intensity, robotZ, sensor));
    stats.roiShapes = drawRoi(header.roi, robotZ);
    stats.lastSweep = header.sweep;
    stats.pointsDrawn = kept.drawn();
    drewSweep = header.sweep;
    dirty = true;
    showCounters();
  }

  function onRaw(header, xyz) {
    raw.set(xyz, null);
    stats.rawDrawn = raw.drawn();
    stats.rawSweep = header.sweep;
    setText('raw-counters', 'decoded points before the ROI: ' + stats.rawDrawn + ' drawn of sweep ' + header.sweep);
    dirty = true;
  }

  function onTrajectory(header, xy) {
    var n = header.n, positions = new Float32Array(3 * n);
    for (var i = 0; i < n; ++i) {
      positions[3 * i] = xy[2 * i];
      positions[3 * i + 1] = xy[2 * i + 1];
      positions[3 * i + 2] = robotZ;
    }
    var g = trajectoryLine.geometry;
    var attribute = new THREE.BufferAttribute(positions, 3);
    g.setAttribute ? g.setAttribute('position', attribute) : g.addAttribute('position', attribute);
    g.setDrawRange(0, n);
    stats.trajectoryId = header.id;
    dirty = true;
  }

  function onStatus(s) {
    setText('state', s.state);
    var faults = document.getElementById('faults');
    faults.textContent = '';
    s.faults.forEach(function (f) {
      var li = document.createElement('li');
      li.textContent = f;
      faults.appendChild(li);
    });
    var figures = [
      'sweeps/s ' + fixed(s.sweeps_per_s, 1),
      'kept ' + fixed(s.kept_pct, 1) + ' %',
      'latency p50 ' + fixed(s.latency_ms_p50, 1) + ' ms · p99 ' + fixed(s.latency_ms_p99, 1) + ' ms',
      'trajectory ' + s.trajectory_id + (s.replay ? ' · replay' : ''),
    ];
    document.getElementById('figures').innerHTML = '';
    figures.forEach(function (t) {
      var span = document.createElement('span');
      span.textContent = t;
      document.getElementById('figures').appendChild(span);
    });
    var pose = ['pose (' + s.pose_source + ') ' + (s.pose_valid ? 'valid' : 'NOT valid: ' + s.pose_status)];
    if (s.pose_age_s !== null) pose.push('age ' + fixed(s.pose_age_s, 2) + ' s');
    if (s.fix_type >= 0) pose.push('fix ' + s.fix_type + (s.h_acc_m !== null ? ', hAcc ' + fixed(s.h_acc_m, 2) + ' m' : ''));
    if (s.rtk_solution >= 0) pose.push('RTK ' + (RTK[s.rtk_solution] || '?'));
    setText('pose', pose.join(' · '));
    var corrections = [];
    if (s.corrections) {
      corrections.push('corrections: ' + s.corrections);
      corrections.push('age ' + (s.correction_age_s === null ? 'none written' : fixed(s.correction_age_s, 1) + ' s'));
      if (s.corrections_bytes_per_s !== null) corrections.push(fixed(s.corrections_bytes_per_s, 0) + ' B/s');
    }
    setText('corrections', corrections.join(' · '));
    setText('time', timeText(s));
  }

  // The time's quality in words: the host clock against GNSS time and against the VLP-16's.
  function timeText(s) {
    var ms = function (v) {
      return (v >= 0 ? '+' : '') + (Math.abs(v) >= 10 ? fixed(v, 1) + ' s' : fixed(1000 * v, 1) + ' ms');
    };
    var parts = [];
    if (s.host_minus_gnss_utc_s !== null) {
      parts.push('host − GNSS ' + ms(s.host_minus_gnss_utc_s) +
                 (s.gnss_time_accuracy_s !== null ? ' (tAcc ' + fixed(1e9 * s.gnss_time_accuracy_s, 0) + ' ns)' : ''));
    }
    if (s.host_minus_lidar_utc_s !== null) parts.push('host − LiDAR ' + ms(s.host_minus_lidar_utc_s));
    if (s.lidar_pps_status >= 0) parts.push('LiDAR PPS ' + (PPS[s.lidar_pps_status] || '?'));
    if (s.lidar_gprmc_valid >= 0) parts.push('GPRMC ' + (s.lidar_gprmc_valid ? 'valid' : 'invalid'));
    return parts.length ? 'time: ' + parts.join(' · ') : 'time: no GNSS or LiDAR time yet';
  }

  function onPose(p) {
    if (!p.valid) setText('pose', 'pose (' + p.pose_source + ') NOT valid: ' + p.status_text);
  }

  // ---- the connection
  var lastFrameAt = 0, connected = false, socket = null;
  function parse(buffer) {
    var view = new DataView(buffer);
    if (buffer.byteLength < 12 || view.getUint32(0, true) !== MAGIC) return;
    var kind = view.getUint32(4, true), length = view.getUint32(8, true);
    var header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 12, length)));
    var at = 12 + length;
    lastFrameAt = performance.now();
    var paused = document.getElementById('pause').checked;
    if (kind === KIND.sweep) {
      if (paused) return;
      var xyz = new Float32Array(buffer, at, 3 * header.n);
      var sensorAt = at + 12 * header.n + Math.ceil(header.n / 4) * 4;  // after the intensities, 4-aligned
      onSweep(header, xyz, new Uint8Array(buffer, at + 12 * header.n, header.n),
              new Uint8Array(buffer, sensorAt, header.n));
    } else if (kind === KIND.raw) {
      if (paused) return;
      onRaw(header, new Float32Array(buffer, at, 3 * header.n));
    } else if (kind === KIND.trajectory) {
      onTrajectory(header, new Float32Array(buffer, at, 2 * header.n));
    } else if (kind === KIND.status) {
      onStatus(header);
    } else if (kind === KIND.pose) {
      onPose(header);
    }
  }

  function connect() {
    var url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws';
    socket = new WebSocket(url);
    socket.binaryType = 'arraybuffer';
    socket.onopen = function () { connected = true; lastFrameAt = performance.now(); };
    socket.onmessage = function (e) { if (e.data instanceof ArrayBuffer) parse(e.data); };
    socket.onclose = function () {
      connected = false;
      setText('connection', 'disconnected from trajroi view at ' + location.host + ': reconnecting…');
      document.getElementById('connection').className = 'bad';
      setTimeout(connect, 1000);
    };
  }
  connect();

  setInterval(function () {
    if (!connected) return;
    var quiet = (performance.now() - lastFrameAt) / 1000;
    var c = document.getElementById('connection');
    if (quiet > 2) {
      c.textContent = 'connected to ' + location.host + ', but no data from trajroid for ' + quiet.toFixed(0) +
                      ' s (is trajroid running, on the LCM URL trajroi view listens to?)';
      c.className = 'bad';
    } else {
      c.textContent = 'connected to ' + location.host + ' · drawn ' + stats.drawnPerSecond + ' sweeps/s';
      c.className = '';
    }
  }, 500);

  var drawnAtSecond = 0;
  setInterval(function () {
    stats.drawnPerSecond = stats.sweepsDrawn - drawnAtSecond;
    drawnAtSecond = stats.sweepsDrawn;
  }, 1000);

  // ---- the controls on the panel
  Array.prototype.forEach.call(document.querySelectorAll('input[name=colour]'), function (r) {
    r.addEventListener('change', function () {
      colourBy = r.value;
      if (lastIntensity) {
        kept.set(lastIntensity.xyz, colours(lastIntensity.xyz, lastIntensity.intensity, robotZ, lastIntensity.sensor));
      }
      dirty = true;
    });
  });
  document.getElementById('top').addEventListener('click', function () {
    topDown(camera.position.distanceTo(controls.target));
  });
  controls.addEventListener('change', function () { dirty = true; });

  function frame() {
    requestAnimationFrame(frame);
    if (!dirty) return;
    dirty = false;
    renderer.render(scene, camera);
    ++stats.framesDrawn;
    if (drewSweep !== null) {
      ++stats.sweepsDrawn;
      if (socket && socket.readyState === 1) socket.send('drawn ' + drewSweep);
      drewSweep = null;
    }
  }
  resize();
  requestAnimationFrame(frame);
})();
