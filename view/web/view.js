// cohaptic's live view: decodes the view server's messages (proto/cohaptic/view.proto, with
// protobufjs) and draws them with three.js: the deformed surface coloured by |u| (or by the
// deformation, the best-fit rigid motion removed), each user's translucent tool, force arrow,
// patch and contact nodes, the held nodes, the obstacles, a separating object's interface
// (its separated faces, the crack front and the laser's grooves), a scale bar; a strip chart and a
// status table per user; for a recording, a timeline whose controls send Commands back.
// Lengths arrive in m and are drawn in the scene's unit; forces in N.
// window.cohapticView exposes the page's state (the browser test reads it).
import * as THREE from 'three';
import { OrbitControls } from '/lib/OrbitControls.js';

const USER_COLOURS = ['#e4572e', '#17bebb', '#ffc914', '#76b041', '#b07bd8', '#f28fb1'];
const CHART_SPAN_S = 10;
// The displacement colour map (viridis at five stops), as the legend's gradient.
const COLOUR_STOPS = [[0x44, 0x01, 0x54], [0x3b, 0x52, 0x8b], [0x21, 0x91, 0x8c], [0x5e, 0xc9, 0x62], [0xfd, 0xe7, 0x25]];
// A non-zero force's arrow is at least this fraction of the arrow scale's length (and the
// tool's radius), so that a small force still shows well outside its tool.
const ARROW_MIN_FRACTION = 0.25;
const SCALE_BAR_PX = 120;  // the scale bar's longest length
// A separating interface, drawn over the layers that hide it (opaque, after the surface,
// before the translucent tools): separated faces (darker where a face is only partly
// separated), the crack front (where open faces meet connected ones) and the laser's grooves.
const SEPARATED_COLOUR = new THREE.Color('#ff8a65');
const CRACK_COLOUR = new THREE.Color('#00e5ff');
const GROOVE_COLOUR = new THREE.Color('#ffffff');

const $ = (id) => document.getElementById(id);
// The eight corners of a THREE.Box3.
const boxCorners = (box) => [0, 1, 2, 3, 4, 5, 6, 7].map((k) => new THREE.Vector3(
  k & 1 ? box.max.x : box.min.x, k & 2 ? box.max.y : box.min.y, k & 4 ? box.max.z : box.min.z));

// ---- the schema ----

async function loadSchema() {
  const root = new protobuf.Root();
  root.resolvePath = (origin, target) => (target.startsWith('/') ? target : '/proto/' + target);
  await root.load('/proto/cohaptic/view.proto', { keepCase: true });
  return {
    ServerMessage: root.lookupType('cohaptic.view.ServerMessage'),
    Command: root.lookupType('cohaptic.view.Command'),
    Protocol: root.lookupEnum('cohaptic.wire.Protocol'),
  };
}

// ---- numbers ----

function niceCeiling(x) {
  if (!(x > 0)) return 1;
  const power = Math.pow(10, Math.floor(Math.log10(x)));
  for (const step of [1, 2, 5, 10]) if (step * power >= x * (1 - 1e-9)) return step * power;
  return 10 * power;
}

function niceFloor(x) {
  if (!(x > 0)) return 1;
  const power = Math.pow(10, Math.floor(Math.log10(x)));
  for (const step of [5, 2, 1]) if (step * power <= x * (1 + 1e-9)) return step * power;
  return power;
}

// A round length or force as text, without float noise (0.30000000000000004).
const round = (x) => String(Number(x.toPrecision(3)));

function colourOf(t, out, offset) {
  const x = Math.min(Math.max(t, 0), 1) * (COLOUR_STOPS.length - 1);
  const i = Math.min(Math.floor(x), COLOUR_STOPS.length - 2), f = x - i;
  for (let c = 0; c < 3; ++c) out[offset + c] = (COLOUR_STOPS[i][c] * (1 - f) + COLOUR_STOPS[i + 1][c] * f) / 255;
}

// protobufjs gives 64-bit integers as {low, high} objects, and a field at its default (0)
// not at all.
const num = (x) => (x === undefined ? 0 : typeof x === 'object' && x !== null ? x.high * 4294967296 + (x.low >>> 0) : Number(x));
const norm3 = (v) => (v && v.length === 3 ? Math.hypot(v[0], v[1], v[2]) : 0);
const fmt = (x, digits) => (Number.isFinite(x) ? x.toFixed(digits) : '–');

// ---- the rigid motion ----

// The unit eigenvector of a symmetric 4x4 matrix's largest eigenvalue (cyclic Jacobi; `a` is overwritten).
function largestEigenvector(a) {
  const v = [0, 1, 2, 3].map((i) => [0, 1, 2, 3].map((j) => (i === j ? 1 : 0)));
  for (let sweep = 0; sweep < 50; ++sweep) {
    let off = 0, all = 0;
    for (let p = 0; p < 4; ++p) for (let q = 0; q < 4; ++q) { all += a[p][q] * a[p][q]; if (p !== q) off += a[p][q] * a[p][q]; }
    if (off <= 1e-28 * all) break;
    for (let p = 0; p < 3; ++p) for (let q = p + 1; q < 4; ++q) {
      if (a[p][q] === 0) continue;
      const theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
      const t = (theta >= 0 ? 1 : -1) / (Math.abs(theta) + Math.sqrt(theta * theta + 1));
      const c = 1 / Math.sqrt(t * t + 1), s = t * c;
      for (let k = 0; k < 4; ++k) {
        const kp = a[k][p], kq = a[k][q];
        a[k][p] = c * kp - s * kq; a[k][q] = s * kp + c * kq;
      }
      for (let k = 0; k < 4; ++k) {
        const pk = a[p][k], qk = a[q][k];
        a[p][k] = c * pk - s * qk; a[q][k] = s * pk + c * qk;
      }
      for (let k = 0; k < 4; ++k) {
        const kp = v[k][p], kq = v[k][q];
        v[k][p] = c * kp - s * kq; v[k][q] = s * kp + c * kq;
      }
    }
  }
  let best = 0;
  for (let i = 1; i < 4; ++i) if (a[i][i] > a[best][best]) best = i;
  return v.map((row) => row[best]);
}

// Writes to `out` the displacement `u` of nodes first..first+count-1 less the rigid motion
// that best carries their rest positions `rest` to rest + u (least squares: Horn's
// quaternion method), what is left being the deformation.
function removeRigidMotion(rest, u, first, count, out) {
  const restCentre = [0, 0, 0], movedCentre = [0, 0, 0];
  for (let i = first; i < first + count; ++i)
    for (let c = 0; c < 3; ++c) { restCentre[c] += rest[3 * i + c] / count; movedCentre[c] += (rest[3 * i + c] + u[3 * i + c]) / count; }
  const S = [[0, 0, 0], [0, 0, 0], [0, 0, 0]];  // sum of (rest - its centre)(moved - its centre)^T
  for (let i = first; i < first + count; ++i)
    for (let a = 0; a < 3; ++a) for (let b = 0; b < 3; ++b)
      S[a][b] += (rest[3 * i + a] - restCentre[a]) * (rest[3 * i + b] + u[3 * i + b] - movedCentre[b]);
  const [[xx, xy, xz], [yx, yy, yz], [zx, zy, zz]] = S;
  const q = largestEigenvector([
    [xx + yy + zz, yz - zy, zx - xz, xy - yx],
    [yz - zy, xx - yy - zz, xy + yx, zx + xz],
    [zx - xz, xy + yx, -xx + yy - zz, yz + zy],
    [xy - yx, zx + xz, yz + zy, -xx - yy + zz]]);
  const R = new THREE.Matrix4().makeRotationFromQuaternion(new THREE.Quaternion(q[1], q[2], q[3], q[0])).elements;
  for (let i = first; i < first + count; ++i) {
    const r = [0, 1, 2].map((c) => rest[3 * i + c] - restCentre[c]);
    for (let c = 0; c < 3; ++c)
      out[3 * i + c] = rest[3 * i + c] + u[3 * i + c] - movedCentre[c] - (R[c] * r[0] + R[4 + c] * r[1] + R[8 + c] * r[2]);
  }
}

// ---- the page ----

class View {
  constructor(schema) {
    this.schema = schema;
    this.state = {
      connected: false, frozen: false, softwareRenderer: false, scene: null, replay: false, framesReceived: 0, framesDrawn: 0, frame: null,
      status: {}, timeline: null, drawFps: 0, messageBytes: 0, displacementScaleMm: 0.1, deformationScaleMm: 0.1, closedReason: '',
      rigidMotionRemoved: false, forceScaleN: 0.01, arrowScale: null, scaleBar: null,
    };
    this.history = new Map();  // slot -> [{t, f}] (live: from frames)
    this.pendingFrame = null;
    this.showObstacles = true;
    this.setUpRenderer();
    this.setUpControls();
    this.connect();
    requestAnimationFrame((t) => this.draw(t));
  }

  setUpRenderer() {
    this.canvas = $('canvas');
    // Multisampling is nearly free on a graphics card but costs a software renderer (a headless
    // browser's SwiftShader) most of its time: only with a card.
    const probe = document.createElement('canvas').getContext('webgl2');
    const info = probe && probe.getExtension('WEBGL_debug_renderer_info');
    this.state.softwareRenderer = !!(info && /swiftshader|llvmpipe/i.test(probe.getParameter(info.UNMASKED_RENDERER_WEBGL)));
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: !this.state.softwareRenderer, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    this.scene3d = new THREE.Scene();
    this.scene3d.background = new THREE.Color(0x15171c);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.1, 1e5);
    this.camera.up.set(0, 0, 1);
    this.orbit = new OrbitControls(this.camera, this.canvas);
    // Drawn only when something changed (a frame, the camera, the window): an idle page costs nothing.
    this.orbit.addEventListener('change', () => { this.needsRender = true; });
    this.scene3d.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.6));
    this.light = new THREE.DirectionalLight(0xffffff, 1.4);
    this.scene3d.add(this.light);
    this.scene3d.add(this.light.target);
    window.addEventListener('resize', () => this.resize());
    this.resize();
  }

  resize() {
    const { clientWidth: w, clientHeight: h } = this.canvas.parentElement;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / Math.max(h, 1);
    this.camera.updateProjectionMatrix();
    this.needsRender = true;
  }

  setUpControls() {
    const send = (body) => this.send(body);
    $('play').addEventListener('click', () => send(this.state.timeline?.playing ? { pause: {} } : { play: {} }));
    $('speed').addEventListener('change', (e) => send({ speed: Number(e.target.value) }));
    $('scrub').addEventListener('input', (e) => send({ seek: Number(e.target.value) }));
    $('jump-peak').addEventListener('click', () => send({ jump: 1 }));
    $('jump-step').addEventListener('click', () => send({ jump: 2 }));
    $('rigid-removed').addEventListener('change', (e) => this.setRigidMotionRemoved(e.target.checked));
    window.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
      const t = this.state.timeline;
      const key = e.key.toLowerCase();
      if (key === 'r') this.resetCamera();
      else if (key === 'o') this.toggleObstacles();
      else if (key === 'f') this.frozen = !this.frozen;
      else if (key === 't') this.focusTools();
      else if (key === 'd') this.setRigidMotionRemoved(!this.state.rigidMotionRemoved);
      else if (!this.state.replay || !t) return;
      else if (e.key === ' ') send(t.playing ? { pause: {} } : { play: {} });
      else if (e.key === 'ArrowLeft' || e.key === 'ArrowRight')
        send({ seek: t.time + (e.key === 'ArrowLeft' ? -1 : 1) * (e.shiftKey ? 0.1 : 1) });
      else if (key === 'p') send({ jump: 1 });
      else if (key === 'j') send({ jump: 2 });
      else return;
      e.preventDefault();
    });
  }

  // ---- the connection ----

  connect() {
    const token = new URLSearchParams(location.search).get('token');
    const url = `ws://${location.host}/ws${token ? `?token=${encodeURIComponent(token)}` : ''}`;
    const ws = new WebSocket(url);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    ws.onopen = () => { this.state.connected = true; this.banner(''); };
    ws.onmessage = (e) => this.receive(new Uint8Array(e.data));
    ws.onclose = (e) => {
      this.state.connected = false;
      this.state.closedReason = e.reason || String(e.code);
      this.banner(this.state.scene ? 'the session has ended (or the server went away): retrying…' : 'no view server: retrying…');
      setTimeout(() => this.connect(), 1000);
    };
  }

  send(body) {
    if (!this.ws || this.ws.readyState !== WebSocket.OPEN) return false;
    const message = this.schema.Command.create(body);
    this.ws.send(this.schema.Command.encode(message).finish());
    return true;
  }

  banner(text) {
    $('connection').textContent = text;
    $('connection').classList.toggle('hidden', !text);
  }

  receive(bytes) {
    this.state.messageBytes += bytes.length;
    const message = this.schema.ServerMessage.decode(bytes);
    if (message.scene) this.setScene(message.scene);
    else if (message.frame) {
      ++this.state.framesReceived;
      this.pendingFrame = message.frame;
      if (!this.state.replay) this.remember(message.frame);
    } else if (message.status) this.setStatus(message.status);
    else if (message.timeline) this.setTimeline(message.timeline);
  }

  // ---- the scene ----

  setScene(scene) {
    const unit = 1 / scene.metres_per_unit;
    this.unit = unit;
    this.units = scene.units;
    this.state.scene = {
      name: scene.scene_name, units: scene.units, source: scene.source, nodes: scene.rest_positions.length / 3,
      triangles: scene.triangles.length / 3, tools: scene.tools.map((t) => ({ slot: t.slot, name: t.name, radius: t.radius })),
      obstacles: scene.obstacles.map((o) => o.name), protocol: this.schema.Protocol.valuesById[scene.protocol] || '?',
      forceLimit: scene.force_limit, frameRateHz: scene.frame_rate_hz,
      objects: scene.objects.map((o) => ({ name: o.name, model: o.model, firstNode: o.first_node, nodes: o.node_count })),
    };
    this.state.replay = scene.source !== 'live';
    this.series = new Map(scene.force_series.map((s) => [s.slot, { times: s.times, magnitudes: s.magnitudes }]));
    this.state.timeline = null;
    document.body.classList.toggle('replay', this.state.replay);
    if (this.root) this.scene3d.remove(this.root);
    this.root = new THREE.Group();
    this.scene3d.add(this.root);
    this.history.clear();

    const n = scene.rest_positions.length / 3;
    this.rest = Float32Array.from(scene.rest_positions, (x) => x * unit);
    this.restMetres = Float64Array.from(scene.rest_positions);
    // Each object moves as a body of its own (a recording made before the objects were listed: one body).
    this.bodies = scene.objects.length ? scene.objects.map((o) => [o.first_node, o.node_count]) : [[0, n]];
    this.lastFrame = null;
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(this.rest.slice(), 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    geometry.setIndex(scene.triangles);
    for (let i = 0; i < n; ++i) colourOf(0, geometry.attributes.color.array, 3 * i);
    geometry.computeVertexNormals();
    geometry.computeBoundingBox();
    this.surface = new THREE.Mesh(geometry, new THREE.MeshPhongMaterial({ vertexColors: true, side: THREE.DoubleSide, shininess: 25 }));
    this.root.add(this.surface);
    this.box = geometry.boundingBox.clone();
    this.size = this.box.getSize(new THREE.Vector3()).length();
    // A force arrow starts at its tool's surface; the round force at or above the largest seen
    // (a recording's from the start) is a round twentieth of the object's diagonal long.
    this.arrowReference = niceCeiling(this.size / 20);
    for (const s of this.series.values()) for (const m of s.magnitudes) this.growForceScale(m);
    this.showArrowScale();

    this.obstacleGroup = new THREE.Group();
    for (const obstacle of scene.obstacles) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(obstacle.vertices, (x) => x * unit), 3));
      g.setIndex(obstacle.triangles);
      g.computeVertexNormals();
      const material = new THREE.MeshPhongMaterial({ color: 0x9fb4c8, transparent: true, opacity: 0.13, depthWrite: false, side: THREE.DoubleSide });
      this.obstacleGroup.add(new THREE.Mesh(g, material));
    }
    this.obstacleGroup.visible = this.showObstacles;
    this.root.add(this.obstacleGroup);
    this.interfaces = scene.interfaces.map((face) => this.makeInterface(face, unit));
    this.state.interfaces = [];

    const pointSize = Math.max(this.size / 160, 0.5);
    const points = (colour, size) => {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
      g.setDrawRange(0, 0);
      const p = new THREE.Points(g, new THREE.PointsMaterial({ color: colour, size, sizeAttenuation: true, depthTest: false }));
      p.renderOrder = 2;
      this.root.add(p);
      return p;
    };
    this.heldPoints = points(0xff4fd8, pointSize);
    this.users = scene.tools.map((tool, k) => {
      const colour = new THREE.Color(USER_COLOURS[k % USER_COLOURS.length]);
      const radius = tool.radius > 0 ? tool.radius * unit : this.size / 150;
      // Translucent, so that the dent under the tool shows through it, and outlined by a ring
      // that faces the camera.
      const sphere = new THREE.Mesh(new THREE.SphereGeometry(radius, 24, 16),
        new THREE.MeshPhongMaterial({ color: colour, transparent: true, opacity: 0.35, depthWrite: false }));
      sphere.visible = false;
      sphere.renderOrder = 1;
      const outline = new THREE.Mesh(new THREE.RingGeometry(radius * 0.94, radius, 48), new THREE.MeshBasicMaterial({ color: colour, side: THREE.DoubleSide }));
      sphere.add(outline);
      this.root.add(sphere);
      const arrow = this.makeArrow(colour);
      this.root.add(arrow);
      const patch = points(colour.clone().lerp(new THREE.Color(0xffffff), 0.55), pointSize);
      const contact = points(0xffffff, pointSize * 1.8);
      const label = document.createElement('div');
      label.className = 'label';
      label.style.background = USER_COLOURS[k % USER_COLOURS.length];
      label.textContent = tool.name;
      $('labels').appendChild(label);
      return { slot: tool.slot, tool: tool.name, colour: USER_COLOURS[k % USER_COLOURS.length], sphere, outline, radius, arrow, patch, contact, label,
               present: false, force: [0, 0, 0], position: null, pressing: false };
    });
    for (const old of [...$('labels').children]) if (!this.users.some((u) => u.label === old)) old.remove();
    this.buildPanel();
    this.resetCamera();
    $('scene-name').textContent = `${scene.scene_name}${this.state.replay ? ' · recording' : ' · live'}`;
    const injected = scene.injected || {};
    // The objects shown (a recording made before they were listed has none).
    const objects = scene.objects.map((o) => `${o.name} (${o.model.replace('_', ' ')}, ${o.node_count} nodes)`).join(', ');
    $('session').textContent = `${this.state.scene.protocol} · ${objects || `${n} surface nodes`} · force limit ${fmt(scene.force_limit, 2)} N` +
      (this.state.replay ? ` · ${scene.source}` : '');
    $('injected').textContent = `injected: shift ${fmt(injected.shift_delay_ms || 0, 1)} ms, jitter ${fmt(injected.jitter_ms || 0, 1)} ms, ` +
      `loss ${fmt(100 * (injected.loss || 0), 1)} %, step nodes ${injected.step_nodes || 0}, ` +
      `sim cap ${injected.sim_rate_hz ? fmt(injected.sim_rate_hz, 0) + ' Hz' : 'none'}`;
  }

  // An arrow along +y from its origin, of unit length until placed: a shaft and a head, drawn
  // over everything (after the translucent tools) in the user's own colour.
  // ---- a separating interface ----

  makeInterface(face, unit) {
    const vertices = Float32Array.from(face.vertices, (x) => x * unit);
    const triangles = face.triangles;
    const count = triangles.length / 3;
    // Each edge with the faces on either side (-1: the interface's rim).
    const edges = new Map();
    for (let t = 0; t < count; ++t)
      for (let k = 0; k < 3; ++k) {
        const a = triangles[3 * t + k], b = triangles[3 * t + (k + 1) % 3];
        const key = a < b ? `${a},${b}` : `${b},${a}`;
        const edge = edges.get(key);
        if (edge) edge.faces[1] = t;
        else edges.set(key, { a, b, faces: [t, -1] });
      }
    const overlay = (geometry, material, order) => {
      const object = material.isLineBasicMaterial ? new THREE.LineSegments(geometry, material) : new THREE.Mesh(geometry, material);
      geometry.setDrawRange(0, 0);
      object.renderOrder = order;
      object.frustumCulled = false;
      this.root.add(object);
      return object;
    };
    const faces = new THREE.BufferGeometry();
    faces.setAttribute('position', new THREE.BufferAttribute(new Float32Array(9 * count), 3));
    faces.setAttribute('color', new THREE.BufferAttribute(new Float32Array(9 * count), 3));
    const front = new THREE.BufferGeometry();
    front.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * edges.size), 3));
    const normal = new THREE.Vector3();
    if (count > 0) {
      const corner = (k) => new THREE.Vector3().fromArray(vertices, 3 * triangles[k]);
      normal.crossVectors(corner(1).sub(corner(0)), corner(2).sub(corner(0))).normalize();
    }
    return {
      object: face.object, vertices, triangles, count, edges: [...edges.values()], normal,
      faces: overlay(faces, new THREE.MeshBasicMaterial({ vertexColors: true, depthTest: false, depthWrite: false, side: THREE.DoubleSide }), 3),
      front: overlay(front, new THREE.LineBasicMaterial({ color: CRACK_COLOUR, depthTest: false, depthWrite: false }), 5),
      grooves: overlay(new THREE.BufferGeometry(), new THREE.MeshBasicMaterial({ color: GROOVE_COLOUR, depthTest: false, depthWrite: false, side: THREE.DoubleSide }), 4),
    };
  }

  applyInterface(face, data) {
    const share = data.separated;
    const open = (t) => t >= 0 && t < share.length && share[t] > 0;
    const positions = face.faces.geometry.attributes.position.array;
    const colours = face.faces.geometry.attributes.color.array;
    let shown = 0, separated = 0;
    for (let t = 0; t < face.count; ++t) {
      if (!open(t)) continue;
      if (share[t] >= 1) ++separated;
      const shade = 0.45 + 0.55 * Math.min(share[t], 1);
      for (let k = 0; k < 3; ++k) {
        const at = 9 * shown + 3 * k;
        for (let c = 0; c < 3; ++c) positions[at + c] = face.vertices[3 * face.triangles[3 * t + k] + c];
        colours[at] = SEPARATED_COLOUR.r * shade;
        colours[at + 1] = SEPARATED_COLOUR.g * shade;
        colours[at + 2] = SEPARATED_COLOUR.b * shade;
      }
      ++shown;
    }
    face.faces.geometry.attributes.position.needsUpdate = true;
    face.faces.geometry.attributes.color.needsUpdate = true;
    face.faces.geometry.setDrawRange(0, 3 * shown);

    const line = face.front.geometry.attributes.position.array;
    let fronts = 0;
    for (const edge of face.edges) {
      const [left, right] = edge.faces;
      if (right < 0 || open(left) === open(right)) continue;
      line.set(face.vertices.subarray(3 * edge.a, 3 * edge.a + 3), 6 * fronts);
      line.set(face.vertices.subarray(3 * edge.b, 3 * edge.b + 3), 6 * fronts + 3);
      ++fronts;
    }
    face.front.geometry.attributes.position.needsUpdate = true;
    face.front.geometry.setDrawRange(0, 2 * fronts);

    // A groove: a flat strip of its width along its segment, in the interface's plane.
    const segments = data.groove_widths.length;
    const strips = new Float32Array(18 * segments);
    const a = new THREE.Vector3(), b = new THREE.Vector3(), across = new THREE.Vector3();
    for (let g = 0; g < segments; ++g) {
      a.fromArray(data.grooves, 6 * g).multiplyScalar(this.unit);
      b.fromArray(data.grooves, 6 * g + 3).multiplyScalar(this.unit);
      across.subVectors(b, a).cross(face.normal).normalize().multiplyScalar(0.5 * data.groove_widths[g] * this.unit);
      const corners = [a.clone().sub(across), a.clone().add(across), b.clone().add(across), b.clone().sub(across)];
      [0, 1, 2, 0, 2, 3].forEach((k, i) => corners[k].toArray(strips, 18 * g + 3 * i));
    }
    face.grooves.geometry.setAttribute('position', new THREE.BufferAttribute(strips, 3));
    face.grooves.geometry.setDrawRange(0, 6 * segments);
    return {
      object: face.object, triangles: face.count, openTriangles: shown, separatedTriangles: separated, frontEdges: fronts,
      grooveSegments: segments, separatedAreaMm2: data.separated_area * 1e6,
    };
  }

  makeArrow(colour) {
    const material = new THREE.MeshBasicMaterial({ color: colour, depthTest: false, transparent: true });
    const shaft = new THREE.Mesh(new THREE.CylinderGeometry(1, 1, 1, 12).translate(0, 0.5, 0), material);
    const head = new THREE.Mesh(new THREE.ConeGeometry(1, 1, 16).translate(0, -0.5, 0), material);
    const arrow = new THREE.Group();
    arrow.add(shaft, head);
    arrow.traverse((o) => { o.renderOrder = 3; });
    arrow.visible = false;
    return arrow;
  }

  placeArrow(arrow, origin, direction, length) {
    const ref = this.arrowReference;
    const [shaft, head] = arrow.children;
    const headLength = Math.min(0.2 * ref, 0.5 * length);
    arrow.position.copy(origin);
    arrow.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), direction);
    shaft.scale.set(0.02 * ref, length - headLength, 0.02 * ref);
    head.position.y = length;
    head.scale.set(0.3 * headLength, headLength, 0.3 * headLength);
  }

  growForceScale(magnitude) {
    if (magnitude > 0) this.state.forceScaleN = Math.max(this.state.forceScaleN, niceCeiling(magnitude));
  }

  showArrowScale() {
    const text = `arrow: ${round(this.arrowReference)} ${this.units} = ${round(this.state.forceScaleN)} N`;
    this.state.arrowScale = { text, length: this.arrowReference, forceN: this.state.forceScaleN };
    $('arrow-scale').textContent = text;
  }

  setRigidMotionRemoved(on) {
    this.state.rigidMotionRemoved = on;
    $('rigid-removed').checked = on;
    if (this.lastFrame) this.applyFrame(this.lastFrame);
    this.needsRender = true;
  }

  resetCamera() {
    if (!this.box) return;
    // From behind, to the left and above (the brain's surgeons work at its back), far enough
    // for the object's bounding sphere to fit the narrower of the two fields of view.
    const centre = this.box.getCenter(new THREE.Vector3());
    const halfFov = THREE.MathUtils.degToRad(this.camera.fov / 2);
    const narrowest = Math.min(halfFov, Math.atan(Math.tan(halfFov) * this.camera.aspect));
    const distance = (this.size / 2 / Math.sin(narrowest)) * 1.05;
    this.camera.position.copy(centre).add(new THREE.Vector3(-0.5, -1, 0.55).normalize().multiplyScalar(distance));
    this.camera.near = this.size / 200;
    this.camera.far = this.size * 20;
    this.camera.updateProjectionMatrix();
    this.orbit.target.copy(centre);
    this.orbit.update();
    this.needsRender = true;
  }

  // Closer, at the present tools' midpoint, looking from where the camera is.
  focusTools() {
    const present = (this.users || []).filter((u) => u.present && u.position);
    if (!present.length) return;
    const middle = present.reduce((sum, u) => sum.add(u.position), new THREE.Vector3()).multiplyScalar(1 / present.length);
    const direction = this.camera.position.clone().sub(this.orbit.target).normalize();
    this.orbit.target.copy(middle);
    this.camera.position.copy(middle).add(direction.multiplyScalar(this.size * 0.45));
    this.orbit.update();
    this.needsRender = true;
  }

  toggleObstacles() {
    this.showObstacles = !this.showObstacles;
    if (this.obstacleGroup) this.obstacleGroup.visible = this.showObstacles;
    this.needsRender = true;
  }

  buildPanel() {
    const container = $('users');
    container.innerHTML = '';
    for (const user of this.users) {
      const card = document.createElement('div');
      card.className = 'user';
      card.style.setProperty('--colour', user.colour);
      card.innerHTML = `<h2><span class="name"></span><span class="force"></span></h2><canvas width="600" height="160"></canvas>
        <table>
          <tr><td>haptic rate</td><td data-field="haptic_rate_hz"></td></tr>
          <tr><td>period p99 (timer floor p99)</td><td data-field="period_p99_us"></td></tr>
          <tr><td>missed deadlines</td><td data-field="missed_deadlines"></td></tr>
          <tr><td>IR age p99 (max)</td><td data-field="ir_age_p99_ms"></td></tr>
          <tr><td>one-way delay p99</td><td data-field="one_way_delay_p99_ms"></td></tr>
          <tr><td>peak force</td><td data-field="peak_force"></td></tr>
          <tr><td>ticks at the force limit</td><td data-field="clamped_ticks"></td></tr>
          <tr><td>fades while pushing (longest)</td><td data-field="fades"></td></tr>
          <tr><td>protocol</td><td data-field="protocol"></td></tr>
        </table>`;
      card.querySelector('.name').textContent = `tool ${user.tool}`;
      container.appendChild(card);
      user.card = card;
      user.chart = card.querySelector('canvas');
    }
  }

  // ---- data ----

  remember(frame) {
    for (const u of frame.users) {
      if (!this.history.has(u.slot)) this.history.set(u.slot, []);
      const list = this.history.get(u.slot);
      list.push({ t: frame.time, f: u.present ? norm3(u.force) : NaN });
      while (list.length && list[0].t < frame.time - CHART_SPAN_S - 1) list.shift();
    }
  }

  setStatus(status) {
    for (const s of status.users) {
      const f = s.figures || {};
      this.state.status[s.slot] = { user: s.user, receivedTime: s.received_time, ...f, missed_deadlines: num(f.missed_deadlines), ticks: num(f.ticks) };
    }
    for (const user of this.users || []) this.showStatus(user);
  }

  showStatus(user) {
    const s = this.state.status[user.slot];
    if (!user.card) return;
    const cell = (field) => user.card.querySelector(`[data-field="${field}"]`);
    if (s && s.user) user.card.querySelector('.name').textContent = `${s.user} · tool ${user.tool}`;
    user.label.textContent = s && s.user ? `${s.user} (${user.tool})` : user.tool;
    cell('protocol').textContent = this.state.scene ? this.state.scene.protocol : '';
    if (!s) return;
    cell('haptic_rate_hz').textContent = `${fmt(s.haptic_rate_hz, 1)} Hz`;
    cell('period_p99_us').textContent = `${fmt(s.period_p99_us, 0)} µs (${fmt(s.timer_floor_p99_us, 0)} µs)`;
    cell('missed_deadlines').textContent = `${num(s.missed_deadlines)}`;
    cell('ir_age_p99_ms').textContent = `${fmt(s.ir_age_p99_ms, 1)} ms (${fmt(num(s.ir_age_max_ms), 1)} ms)`;
    cell('one_way_delay_p99_ms').textContent = `${fmt(s.one_way_delay_p99_ms, 2)} ms`;
    cell('peak_force').textContent = `${fmt(s.peak_force, 3)} N${s.final ? ' (final)' : ''}`;
    cell('clamped_ticks').textContent = `${num(s.clamped_ticks)}`;
    cell('fades').textContent = `${num(s.fades)} (${fmt(num(s.fade_longest_s) * 1e3, 0)} ms)`;
  }

  setTimeline(timeline) {
    const first = !this.state.timeline;
    this.state.timeline = {
      start: timeline.start, end: timeline.end, time: timeline.time, playing: timeline.playing, speed: timeline.speed,
      peakForceTime: timeline.peak_force_time, largestStepTime: timeline.largest_step_time,
    };
    if (first && this.series) this.drawScrubChart();
    const scrub = $('scrub');
    scrub.min = timeline.start;
    scrub.max = timeline.end;
    if (document.activeElement !== scrub || first) scrub.value = timeline.time;
    $('play').textContent = timeline.playing ? '❚❚' : '▶';
    $('speed').value = String(timeline.speed);
    $('time').textContent = `${fmt(timeline.time, 2)} / ${fmt(timeline.end, 2)} s`;
  }

  // ---- drawing ----

  applyFrame(frame) {
    const unit = this.unit;
    const positions = this.surface.geometry.attributes.position.array;
    const colours = this.surface.geometry.attributes.color.array;
    this.lastFrame = frame;
    const n = positions.length / 3;
    const u = Float64Array.from({ length: 3 * n }, (_, k) => frame.displacement[k] || 0);
    const largestOf = (field) => {
      let largest = 0;
      for (let i = 0; i < n; ++i) largest = Math.max(largest, Math.hypot(field[3 * i], field[3 * i + 1], field[3 * i + 2]));
      return largest;
    };
    const largest = largestOf(u);
    // A body swinging as a whole hides its dent: with the rigid motion removed, the colour is
    // what is left of u once each body's best-fit rigid motion is taken away.
    const removed = this.state.rigidMotionRemoved;
    const coloured = removed ? u.slice() : u;
    if (removed) for (const [first, count] of this.bodies) removeRigidMotion(this.restMetres, u, first, count, coloured);
    const largestColoured = removed ? largestOf(coloured) : largest;
    // The colour scale grows to the largest seen, in round millimetres.
    const scaleKey = removed ? 'deformationScaleMm' : 'displacementScaleMm';
    this.state[scaleKey] = Math.max(this.state[scaleKey], niceCeiling(largestColoured * 1e3));
    const scaleMm = this.state[scaleKey];
    for (let i = 0; i < n; ++i) {
      for (let c = 0; c < 3; ++c) positions[3 * i + c] = this.rest[3 * i + c] + u[3 * i + c] * unit;
      colourOf(Math.hypot(coloured[3 * i], coloured[3 * i + 1], coloured[3 * i + 2]) * 1e3 / scaleMm, colours, 3 * i);
    }
    this.surface.geometry.attributes.position.needsUpdate = true;
    this.surface.geometry.attributes.color.needsUpdate = true;
    this.surface.geometry.computeVertexNormals();
    $('legend-title').textContent = removed ? 'deformation, rigid motion removed [mm]' : 'displacement |u| [mm]';
    $('legend-max').textContent = fmt(scaleMm, scaleMm < 1 ? 2 : 1);
    $('legend-mid').textContent = fmt(scaleMm / 2, scaleMm < 1 ? 2 : 1);
    for (const data of frame.users) if (data.present) this.growForceScale(norm3(data.force));
    this.showArrowScale();

    const placeNodes = (points, nodes) => {
      const array = points.geometry.attributes.position.array;
      nodes.forEach((node, k) => { for (let c = 0; c < 3; ++c) array[3 * k + c] = positions[3 * node + c]; });
      points.geometry.attributes.position.needsUpdate = true;
      points.geometry.setDrawRange(0, nodes.length);
    };
    placeNodes(this.heldPoints, frame.held_nodes);
    for (const user of this.users) {
      const data = frame.users.find((f) => f.slot === user.slot);
      user.present = !!(data && data.present);
      user.sphere.visible = user.present;
      user.label.style.display = user.present ? '' : 'none';
      if (!user.present) {
        user.arrow.visible = false;
        placeNodes(user.patch, []);
        placeNodes(user.contact, []);
        user.force = [0, 0, 0];
        user.card.querySelector('.force').textContent = 'absent';
        continue;
      }
      const p = new THREE.Vector3(...data.position).multiplyScalar(unit);
      user.position = p;
      user.force = [...data.force];
      user.pressing = data.pressing;
      user.sphere.position.copy(p);
      const magnitude = norm3(data.force);
      user.arrow.visible = magnitude > 0;
      user.arrowLength = 0;
      if (user.arrow.visible) {
        const direction = new THREE.Vector3(...data.force).normalize();
        user.arrowLength = Math.max(this.arrowReference * Math.max(magnitude / this.state.forceScaleN, ARROW_MIN_FRACTION), user.radius);
        user.arrowOrigin = p.clone().addScaledVector(direction, user.radius);
        user.arrowTip = user.arrowOrigin.clone().addScaledVector(direction, user.arrowLength);
        this.placeArrow(user.arrow, user.arrowOrigin, direction, user.arrowLength);
      }
      placeNodes(user.patch, data.patch_nodes);
      placeNodes(user.contact, data.contact_nodes);
      user.card.querySelector('.force').textContent = `${fmt(magnitude, 3)} N`;
    }
    this.state.interfaces = frame.interfaces.map((data) => {
      const face = this.interfaces.find((f) => f.object === data.object);
      return face ? this.applyInterface(face, data) : null;
    }).filter((shown) => shown);
    const boundary = frame.boundary_nodes;
    $('frame-info').textContent = `t = ${fmt(frame.time, 2)} s · simulation ${fmt(frame.sim_rate_hz, 0)} steps/s · |B| = ${boundary}`;
    this.state.frame = {
      time: frame.time, sequence: num(frame.sequence), boundaryNodes: boundary, heldShown: frame.held_nodes.length,
      simRateHz: frame.sim_rate_hz, maxDisplacementMm: largest * 1e3, maxDeformationMm: removed ? largestColoured * 1e3 : null,
    };
  }

  drawChart(user, now) {
    const canvas = user.chart;
    const ctx = canvas.getContext('2d');
    const w = canvas.width, h = canvas.height;
    ctx.clearRect(0, 0, w, h);
    let samples = [];
    if (this.state.replay && this.series?.has(user.slot)) {
      const s = this.series.get(user.slot);
      for (let i = 0; i < s.times.length; ++i)
        if (s.times[i] >= now - CHART_SPAN_S && s.times[i] <= now) samples.push({ t: s.times[i], f: s.magnitudes[i] });
    } else {
      samples = (this.history.get(user.slot) || []).filter((s) => s.t >= now - CHART_SPAN_S);
    }
    const finite = samples.filter((s) => Number.isFinite(s.f));
    const top = niceCeiling(Math.max(0.01, ...finite.map((s) => s.f)));
    ctx.strokeStyle = '#3a404c';
    ctx.fillStyle = '#8a90a0';
    ctx.font = '20px system-ui';
    ctx.lineWidth = 1;
    for (const f of [0.5, 1]) {
      const y = h - 4 - f * (h - 8);
      ctx.beginPath(); ctx.moveTo(0, y); ctx.lineTo(w, y); ctx.stroke();
    }
    ctx.fillText(`${top} N`, 6, 22);
    ctx.fillText(`|F| over the last ${CHART_SPAN_S} s`, w - 250, h - 8);
    ctx.strokeStyle = user.colour;
    ctx.lineWidth = 3;
    ctx.beginPath();
    let drawn = 0, moving = false;
    for (const s of samples) {
      if (!Number.isFinite(s.f)) { moving = false; continue; }
      const x = w - ((now - s.t) / CHART_SPAN_S) * w, y = h - 4 - (s.f / top) * (h - 8);
      if (moving) ctx.lineTo(x, y); else ctx.moveTo(x, y);
      moving = true;
      ++drawn;
    }
    ctx.stroke();
    user.chartState = {
      samples: drawn, first: finite.length ? finite[0].t : NaN, last: finite.length ? finite[finite.length - 1].t : NaN,
      latest: finite.length ? finite[finite.length - 1].f : NaN, top,
    };
  }

  drawScrubChart() {
    const canvas = $('scrub-chart');
    canvas.width = canvas.clientWidth * devicePixelRatio;
    canvas.height = canvas.clientHeight * devicePixelRatio;
    const ctx = canvas.getContext('2d');
    const { start, end } = this.state.timeline;
    const span = Math.max(end - start, 1e-9);
    let top = 1e-6;
    for (const s of this.series.values()) for (const m of s.magnitudes) top = Math.max(top, m);
    for (const user of this.users) {
      const s = this.series.get(user.slot);
      if (!s) continue;
      ctx.strokeStyle = user.colour;
      ctx.lineWidth = devicePixelRatio;
      ctx.beginPath();
      s.times.forEach((t, i) => {
        // Above the slider's track, which takes the lowest 16 px.
        const x = ((t - start) / span) * canvas.width, y = 2 + (canvas.height - 18 * devicePixelRatio) * (1 - s.magnitudes[i] / top);
        if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y);
      });
      ctx.stroke();
    }
  }

  // Each tool's name beside its outline, on the side away from its arrow (above without one),
  // so that the arrow stays in sight.
  placeLabels() {
    const rect = this.canvas.getBoundingClientRect();
    for (const user of this.users || []) {
      if (!user.present || !user.position) continue;
      const centre = this.screenBox([user.position]);
      let dx = 0, dy = -1;
      if (user.arrow.visible) {
        const tip = this.screenBox([user.arrowTip]);
        const apart = Math.hypot(tip.x0 - centre.x0, tip.y0 - centre.y0);
        if (apart > 1) { dx = (centre.x0 - tip.x0) / apart; dy = (centre.y0 - tip.y0) / apart; }
      }
      const reach = this.screenRadius(user.position, user.radius) + 6 +
        Math.abs(dx) * user.label.offsetWidth / 2 + Math.abs(dy) * user.label.offsetHeight / 2;
      user.label.style.left = `${centre.x0 - rect.left + dx * reach}px`;
      user.label.style.top = `${centre.y0 - rect.top + dy * reach}px`;
    }
  }

  // The length of SCALE_BAR_PX pixels or less, rounded, at the depth the camera orbits about.
  placeScaleBar() {
    const depth = this.camera.position.distanceTo(this.orbit.target);
    const unitsPerPixel = (2 * depth * Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2))) / Math.max(this.canvas.clientHeight, 1);
    const length = niceFloor(SCALE_BAR_PX * unitsPerPixel);
    const pixels = length / unitsPerPixel;
    const text = `${round(length)} ${this.units}`;
    $('scale-bar-line').style.width = `${pixels}px`;
    $('scale-bar-text').textContent = text;
    this.state.scaleBar = { text, length, pixels };
  }

  draw(time) {
    requestAnimationFrame((t) => this.draw(t));
    if (!this.surface) return;
    if (this.pendingFrame && !this.frozen) {
      const frame = this.pendingFrame;
      this.pendingFrame = null;
      this.applyFrame(frame);
      ++this.state.framesDrawn;
      this.drawTimes = (this.drawTimes || []).filter((t) => t > time - 2000).concat([time]);
      this.state.drawFps = this.drawTimes.length > 1 ? (this.drawTimes.length - 1) / ((time - this.drawTimes[0]) / 1000) : 0;
      for (const user of this.users) this.drawChart(user, frame.time);
      this.needsRender = true;
    }
    if (!this.needsRender) return;
    this.needsRender = false;
    this.light.position.copy(this.camera.position);
    this.light.target.position.copy(this.orbit.target);
    for (const user of this.users || []) user.outline.quaternion.copy(this.camera.quaternion);
    this.renderer.render(this.scene3d, this.camera);
    this.placeLabels();
    this.placeScaleBar();
  }

  // ---- where things are on the screen (CSS pixels of the page; the browser test reads them too) ----

  screenBox(points) {
    const rect = this.canvas.getBoundingClientRect();
    let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
    for (const q of points) {
      const p = q.clone().project(this.camera);
      const x = rect.left + ((p.x + 1) / 2) * rect.width, y = rect.top + ((1 - p.y) / 2) * rect.height;
      x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
    }
    return { x0, y0, x1, y1 };
  }

  // A sphere's silhouette radius on the screen [CSS pixels].
  screenRadius(centre, radius) {
    const distance = this.camera.position.distanceTo(centre);
    const up = new THREE.Vector3(0, 1, 0).applyQuaternion(this.camera.quaternion);
    const a = this.screenBox([centre]), b = this.screenBox([centre.clone().addScaledVector(up, radius)]);
    return (Math.hypot(b.x0 - a.x0, b.y0 - a.y0) * distance) / Math.sqrt(Math.max(distance * distance - radius * radius, 1e-12));
  }

  snapshot() {
    const box = this.surface ? new THREE.Box3().setFromBufferAttribute(this.surface.geometry.attributes.position) : null;
    const rect = this.canvas.getBoundingClientRect();
    return {
      ...this.state,
      frozen: !!this.frozen,
      canvas: { x: rect.left, y: rect.top, width: rect.width, height: rect.height },
      meshScreenBox: box ? this.screenBox(boxCorners(box)) : null,
      meshTriangles: this.surface ? this.surface.geometry.index.count / 3 : 0,
      interfaceScreenBoxes: (this.interfaces || []).map((face) => this.screenBox(boxCorners(new THREE.Box3().setFromArray(face.vertices)))),
      users: (this.users || []).map((u) => ({
        slot: u.slot, tool: u.tool, colour: u.colour, present: u.present, pressing: u.pressing, force: u.force,
        forceMagnitude: norm3(u.force), arrowVisible: u.arrow.visible, arrowLength: u.arrowLength || 0,
        toolScreen: u.present && u.position ? this.screenBox([u.position]) : null,
        toolScreenRadius: u.present && u.position ? this.screenRadius(u.position, u.radius) : null,
        arrowOriginScreen: u.arrow.visible ? this.screenBox([u.arrowOrigin]) : null,
        arrowTipScreen: u.arrow.visible ? this.screenBox([u.arrowTip]) : null,
        chart: u.chartState || null,
        panel: u.card ? Object.fromEntries([...u.card.querySelectorAll('[data-field]')].map((c) => [c.dataset.field, c.textContent])) : {},
      })),
    };
  }
}

const schema = await loadSchema();
const view = new View(schema);
window.cohapticView = {
  snapshot: () => view.snapshot(),
  command: (body) => view.send(body),
  freeze: (on) => { view.frozen = on; },
};
