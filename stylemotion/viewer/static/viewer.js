// stylemotion viewer: canonical-skeleton motions from data.js drawn with three.js (vendor/).
// Format of window.STYLEMOTION_DATA and the page's behaviour: docs/viewer.md.
(function () {
  "use strict";
  const T = window.THREE;
  const D = window.STYLEMOTION_DATA;
  const errorBox = document.getElementById("error");

  function fail(message) {
    errorBox.textContent = message;
    errorBox.hidden = false;
    document.body.dataset.error = message;
  }
  if (!T || !D) {
    fail(!T ? "three.js did not load (vendor/three.bundle.min.js)" : "data.js did not load");
    return;
  }

  function bytes(b64) {
    const text = atob(b64);
    const out = new Uint8Array(text.length);
    for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
    return out;
  }

  const J = D.joints.length;
  const parents = D.parents;
  const bones = [];
  for (let j = 0; j < J; j++) if (parents[j] >= 0) bones.push([parents[j], j]);
  const feet = D.foot_points;  // [[heel, ball] of left, [heel, ball] of right]
  const motions = D.motions.map((m) => ({
    name: m.name, group: m.group, color: new T.Color(m.color), fps: m.fps, frames: m.frames,
    pos: new Float32Array(bytes(m.positions).buffer), contacts: bytes(m.contacts), path: m.path, targets: m.targets,
    offset: 0,
  }));
  const n = motions.length;
  const displayFps = Math.max(...motions.map((m) => m.fps));
  const duration = Math.max(...motions.map((m) => (m.frames - 1) / m.fps));
  const totalFrames = Math.round(duration * displayFps);

  // renderer, scene, camera
  const host = document.getElementById("view");
  // quality: ?quality=high (antialiasing, shadows) or low; auto (default): low on a software WebGL renderer
  function webglRenderer() {
    const gl = document.createElement("canvas").getContext("webgl2");
    if (!gl) return "";
    const info = gl.getExtension("WEBGL_debug_renderer_info");
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    const lose = gl.getExtension("WEBGL_lose_context");
    if (lose) lose.loseContext();
    return name;
  }
  const asked = new URLSearchParams(window.location.search).get("quality") || "auto";
  const software = /swiftshader|llvmpipe|software/i.test(webglRenderer());
  const high = asked === "high" || (asked !== "low" && !software);
  let renderer;
  try {
    renderer = new T.WebGLRenderer({ antialias: high });
  } catch (e) {
    fail("WebGL is not available in this browser: " + e.message);
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.shadowMap.enabled = high;
  renderer.shadowMap.type = T.PCFShadowMap;
  host.appendChild(renderer.domElement);
  const scene = new T.Scene();
  scene.background = new T.Color(0xf4f4f4);
  const camera = new T.PerspectiveCamera(40, 1, 0.05, 500);
  const controls = new T.OrbitControls(camera, renderer.domElement);
  controls.enableDamping = true;
  scene.add(new T.HemisphereLight(0xffffff, 0x8a8a8a, 1.6));
  const sun = new T.DirectionalLight(0xffffff, 2.2);
  sun.castShadow = true;
  sun.shadow.mapSize.set(2048, 2048);
  scene.add(sun, sun.target);

  // skeletons: one instanced mesh of bones (cylinders) and one of joints (spheres) for all motions
  const boneRadius = 0.025, jointRadius = 0.034;
  const material = new T.MeshStandardMaterial({ color: 0xffffff, roughness: 0.6 });
  const boneMesh = new T.InstancedMesh(new T.CylinderGeometry(1, 1, 1, 10), material, n * bones.length);
  const jointMesh = new T.InstancedMesh(new T.SphereGeometry(1, 14, 10), material, n * J);
  for (const mesh of [boneMesh, jointMesh]) {
    mesh.castShadow = true;
    mesh.frustumCulled = false;
    mesh.instanceMatrix.setUsage(T.DynamicDrawUsage);
    scene.add(mesh);
  }
  const contactColor = new T.Color(0xffc400);
  const isFoot = new Set(feet.flat());
  motions.forEach((m, i) => {
    bones.forEach((_, b) => boneMesh.setColorAt(i * bones.length + b, m.color));
    const jointColor = m.color.clone().lerp(new T.Color(0xffffff), 0.45);
    for (let j = 0; j < J; j++) jointMesh.setColorAt(i * J + j, jointColor);
    m.jointColor = jointColor;
  });

  // ground, grid, walk paths, targets and root tracks (one group per motion, moved with its offset)
  const overlays = motions.map(() => new T.Group());
  overlays.forEach((g) => scene.add(g));
  function groundLine(points, color, opacity) {
    const geometry = new T.BufferGeometry().setFromPoints(points.map((p) => new T.Vector3(p[0], 0.004, p[1])));
    return new T.Line(geometry, new T.LineBasicMaterial({ color, transparent: opacity < 1, opacity }));
  }
  motions.forEach((m, i) => {
    const root = [];
    for (let f = 0; f < m.frames; f++) root.push([m.pos[f * J * 3], m.pos[f * J * 3 + 2]]);
    overlays[i].add(groundLine(root, m.color, 0.35));
    if (m.path) overlays[i].add(groundLine(m.path, m.color, 1));
    for (const t of m.targets || []) {
      const ring = new T.Mesh(new T.RingGeometry(0.07, 0.1, 32),
        new T.MeshBasicMaterial({ color: m.color, side: T.DoubleSide }));
      ring.rotation.x = -Math.PI / 2;
      ring.position.set(t[0], 0.005, t[1]);
      overlays[i].add(ring);
    }
  });
  let ground, grid;

  // layout: side by side (motion i moved i·spacing along +X) or overlaid
  let layout = D.layout;
  function bounds() {
    const box = new T.Box3();
    const v = new T.Vector3();
    motions.forEach((m) => {
      const step = Math.max(1, Math.floor(m.frames / 60));
      for (let f = 0; f < m.frames; f += step) {
        for (let j = 0; j < J; j++) {
          const k = (f * J + j) * 3;
          box.expandByPoint(v.set(m.pos[k] + m.offset, m.pos[k + 1], m.pos[k + 2]));
        }
      }
    });
    return box;
  }
  function applyLayout(fitCamera) {
    motions.forEach((m, i) => {
      m.offset = layout === "side" ? i * D.spacing_m : 0;
      overlays[i].position.x = m.offset;
    });
    const box = bounds();
    const centre = box.getCenter(new T.Vector3());
    const size = box.getSize(new T.Vector3());
    const radius = Math.max(1.5, 0.5 * Math.hypot(size.x, size.y, size.z));
    const extent = Math.ceil(Math.max(size.x, size.z) + 6);
    if (ground) scene.remove(ground, grid);
    ground = new T.Mesh(new T.PlaneGeometry(extent, extent), new T.MeshStandardMaterial({ color: 0xe6e6e6 }));
    ground.rotation.x = -Math.PI / 2;
    ground.receiveShadow = true;
    grid = new T.GridHelper(extent, extent, 0xb0b0b0, 0xcfcfcf);
    grid.position.y = 0.001;
    ground.position.set(Math.round(centre.x), 0, Math.round(centre.z));
    grid.position.set(Math.round(centre.x), 0.001, Math.round(centre.z));
    scene.add(ground, grid);
    sun.position.set(centre.x + 0.4 * radius, 3 * radius, centre.z + 0.8 * radius);
    sun.target.position.set(centre.x, 0, centre.z);
    const cam = sun.shadow.camera;
    cam.left = cam.bottom = -1.2 * radius;
    cam.right = cam.top = 1.2 * radius;
    cam.near = 0.1;
    cam.far = 8 * radius;
    cam.updateProjectionMatrix();
    if (fitCamera) {
      controls.target.set(centre.x, Math.min(centre.y, 0.9), centre.z);
      camera.position.set(centre.x + 0.3 * radius, 0.9 + 0.8 * radius, centre.z + 1.7 * radius);
      controls.update();
    }
    shownFrame = -1;
  }

  // poses
  const up = new T.Vector3(0, 1, 0);
  const a = new T.Vector3(), b = new T.Vector3(), d = new T.Vector3();
  const q = new T.Quaternion(), s = new T.Vector3(), matrix = new T.Matrix4();
  function joint(m, f, j, out) {
    const k = (f * J + j) * 3;
    return out.set(m.pos[k] + m.offset, m.pos[k + 1], m.pos[k + 2]);
  }
  function pose(time) {
    motions.forEach((m, i) => {
      const f = Math.min(m.frames - 1, Math.round(time * m.fps));
      bones.forEach(([p, c], bi) => {
        joint(m, f, p, a);
        joint(m, f, c, b);
        d.subVectors(b, a);
        const length = d.length();
        q.setFromUnitVectors(up, length > 1e-9 ? d.divideScalar(length) : up);
        matrix.compose(a.add(b).multiplyScalar(0.5), q, s.set(boneRadius, length, boneRadius));
        boneMesh.setMatrixAt(i * bones.length + bi, matrix);
      });
      q.identity();
      for (let j = 0; j < J; j++) {
        const touching = isFoot.has(j) && m.contacts[f * 2 + (feet[0].includes(j) ? 0 : 1)] === 1;
        const r = touching ? 1.6 * jointRadius : jointRadius;
        matrix.compose(joint(m, f, j, a), q, s.set(r, r, r));
        jointMesh.setMatrixAt(i * J + j, matrix);
        if (isFoot.has(j)) jointMesh.setColorAt(i * J + j, touching ? contactColor : m.jointColor);
      }
    });
    boneMesh.instanceMatrix.needsUpdate = true;
    jointMesh.instanceMatrix.needsUpdate = true;
    jointMesh.instanceColor.needsUpdate = true;
  }

  // controls
  const state = { time: 0, playing: true, speed: 1 };
  const playButton = document.getElementById("play");
  const speed = document.getElementById("speed");
  const scrub = document.getElementById("scrub");
  const counter = document.getElementById("frame");
  const layoutSelect = document.getElementById("layout");
  scrub.max = String(totalFrames);
  layoutSelect.value = layout;
  function setPlaying(on) {
    state.playing = on;
    playButton.textContent = on ? "Pause" : "Play";
  }
  playButton.addEventListener("click", () => setPlaying(!state.playing));
  speed.addEventListener("change", () => { state.speed = Number(speed.value); });
  scrub.addEventListener("input", () => { state.time = Number(scrub.value) / displayFps; });
  layoutSelect.addEventListener("change", () => { layout = layoutSelect.value; applyLayout(true); });
  window.addEventListener("keydown", (e) => {
    if (e.code === "Space" && e.target === document.body) { e.preventDefault(); setPlaying(!state.playing); }
  });

  // legend
  const legend = document.getElementById("legend");
  motions.forEach((m) => {
    const row = document.createElement("div");
    const swatch = document.createElement("span");
    swatch.className = "swatch";
    swatch.style.background = "#" + m.color.getHexString();
    const label = document.createElement("span");
    const named = m.name.startsWith(m.group) ? m.name : `${m.name} · ${m.group}`;
    label.textContent = `${named} · ${m.frames} frames @ ${m.fps} fps`;
    row.append(swatch, label);
    legend.append(row);
  });
  const note = document.createElement("span");
  note.className = "note";
  note.textContent = "Yellow feet: ground contact. Faint line: root track; solid line and rings: a generated " +
    "walk's path and targets. Drag to orbit, scroll to zoom, right-drag to pan; space plays/pauses.";
  legend.append(note);
  if (!high) {
    const q = document.createElement("span");
    q.className = "note";
    q.textContent = (software ? "Software WebGL: " : "") + "shadows and antialiasing off (add ?quality=high to the " +
      "address to turn them on).";
    legend.append(q);
  }
  document.body.dataset.quality = high ? "high" : "low";

  // resize and render loop
  function resize() {
    const w = host.clientWidth || 1, h = host.clientHeight || 1;
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  new ResizeObserver(resize).observe(host);
  resize();
  let shownFrame = -1;
  applyLayout(true);
  let last = performance.now(), fpsFrames = 0, fpsStart = last;
  const api = {
    skeletons: n, motions: n, totalFrames, displayFps, fps: 0, rendered: 0, quality: high ? "high" : "low",
    frame: () => shownFrame,
    setFrame: (k) => { state.time = Math.max(0, Math.min(totalFrames, k)) / displayFps; },
    play: () => setPlaying(true),
    pause: () => setPlaying(false),
  };
  function tick(now) {
    const dt = Math.min(0.1, (now - last) / 1000);
    last = now;
    if (state.playing && duration > 0) state.time = (state.time + dt * state.speed) % (duration + 1 / displayFps);
    const k = Math.min(totalFrames, Math.round(state.time * displayFps));
    if (k !== shownFrame) {
      pose(k / displayFps);
      shownFrame = k;
      scrub.value = String(k);
      counter.textContent = `frame ${k} / ${totalFrames}`;
      counter.dataset.frame = String(k);
    }
    controls.update();
    renderer.render(scene, camera);
    api.rendered++;
    fpsFrames++;
    if (now - fpsStart >= 1000) {
      api.fps = (1000 * fpsFrames) / (now - fpsStart);
      fpsFrames = 0;
      fpsStart = now;
    }
    requestAnimationFrame(tick);
  }
  window.stylemotionViewer = api;
  document.body.dataset.skeletons = String(boneMesh.count / bones.length);
  requestAnimationFrame((now) => { last = now; fpsStart = now; tick(now); document.body.dataset.ready = "1"; });
})();
