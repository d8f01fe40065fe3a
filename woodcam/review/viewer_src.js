// woodcam review page viewer: three.js scene of a baked part with a section plane whose cap
// shows the wood inside (a 3-D texture of Wood.color evaluated by woodcam), views, a two-click
// measurement in mm, hotspots and a printable shop sheet.
//
// Bundled with three.js by esbuild (`make review-bundle`) into viewer.bundle.js, which the page
// inlines: the page works from file:// with no network. Data comes from the page's
// <script type="application/json" id="woodcam-data"> (see woodcam/review/__init__.py).
//
// Frames: the GLB scene is glTF (metres, Y up; its root node carries BLOCK_TO_GLTF). Block
// coordinates (mm, Z up) are p_block = (1000 x, -1000 z, 1000 y) of a world point (x, y, z).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';

const data = JSON.parse(document.getElementById('woodcam-data').textContent);
const params = new URLSearchParams(location.hash.slice(1));
// the hash is the page's starting state (view, cut, ortho): an edited hash on an open page
// changed nothing until a reload, so a new hash reloads the page
window.addEventListener('hashchange', () => location.reload());
const [W, D, H] = data.block.size_mm;
const status = document.getElementById('status');

function worldOfBlock(x, y, z) { return new THREE.Vector3(x / 1000, z / 1000, -y / 1000); }
function blockOfWorld(p) { return [p.x * 1000, -p.z * 1000, p.y * 1000]; }

const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: !params.has('bare'), stencil: true,
                                           preserveDrawingBuffer: true });
renderer.localClippingEnabled = true;
renderer.setPixelRatio(1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(params.has('bare') ? 0x000000 : 0xe8e4dc);
scene.add(new THREE.HemisphereLight(0xffffff, 0x776655, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(0.3, 0.6, 0.5);
scene.add(sun);

const centre = worldOfBlock(W / 2, D / 2, H / 2);
const span = Math.hypot(W, D, H) / 1000;
const radius = span / 2;  // the block's bounding sphere (m): every view keeps it in frame
const MARGIN = 1.08;  // room round the sphere (the fit of a box's sphere already leaves some)
const persp = new THREE.PerspectiveCamera(35, 1, span / 100, span * 20);
const ortho = new THREE.OrthographicCamera(-1, 1, 1, -1, -span * 10, span * 10);
let camera = params.has('ortho') ? ortho : persp;
const controls = new OrbitControls(camera, canvas);
controls.target.copy(centre);

// width / height of the canvas; 1 while it has no size (hidden, e.g. while printing)
function canvasAspect() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  return w > 0 && h > 0 ? w / h : 1;
}

// Distance (m) from the centre at which the perspective camera sees the whole bounding sphere,
// through the narrower of its vertical and horizontal fields of view.
function perspDistance(aspect) {
  const half = THREE.MathUtils.degToRad(persp.fov / 2);
  return radius * MARGIN / Math.sin(Math.min(half, Math.atan(Math.tan(half) * aspect)));
}

// What the orthographic camera frames, width and height in m: the block face seen square on
// (it fills the frame exactly when the aspect matches, README), else the bounding sphere.
function orthoExtent(name) {
  const face = { front: [W, H], back: [W, H], left: [D, H], right: [D, H], top: [W, D] }[name];
  return face ? [face[0] / 1000, face[1] / 1000] : [2 * radius * MARGIN, 2 * radius * MARGIN];
}

let viewName = 'iso';
function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (!(w > 0 && h > 0)) return;
  renderer.setSize(w, h, false);
  const aspect = w / h;
  // keep the user's dolly: scale the distance by how much the fit changes with the aspect
  const offset = persp.position.clone().sub(controls.target);
  persp.position.copy(controls.target)
    .addScaledVector(offset, perspDistance(aspect) / perspDistance(persp.aspect));
  persp.aspect = aspect;
  persp.updateProjectionMatrix();
  const [ew, eh] = orthoExtent(viewName);
  const half = Math.max(eh, ew / aspect) / 2;
  ortho.left = -half * aspect; ortho.right = half * aspect;
  ortho.top = half; ortho.bottom = -half;
  ortho.updateProjectionMatrix();
  updateProbe();
}

// Views: front looks along block +Y, top down block -Z, iso from front-right-above.
const VIEWS = {
  front: [0, -1, 0], back: [0, 1, 0], left: [-1, 0, 0], right: [1, 0, 0], top: [0, 0, 1],
  iso: [1, -1, 0.8],
};
function setView(name) {
  viewName = Object.hasOwn(VIEWS, name) ? name : 'iso';  // not 'toString' (inherited)
  if (!cut.asked) setCutOn(viewName !== 'top');
  const d = VIEWS[viewName];
  const dir = worldOfBlock(d[0], d[1], d[2]).normalize();
  persp.aspect = canvasAspect();  // resize() below then keeps this distance
  for (const cam of [persp, ortho]) {
    cam.position.copy(centre).addScaledVector(dir, perspDistance(persp.aspect));
    cam.up.set(0, viewName === 'top' ? 0 : 1, viewName === 'top' ? -1 : 0);
    cam.lookAt(centre);
  }
  ortho.zoom = 1;
  controls.target.copy(centre);
  resize();
}

// Test hook: the normalised device coordinates (x0,y0,x1,y1; the frame is -1..1) that the
// block's and the part's bounding boxes span under the camera shown.
let partBox = null;
function ndcBounds(lo, hi) {
  const b = new THREE.Box2();
  for (let i = 0; i < 8; i++) {
    const p = new THREE.Vector3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const q = p.project(camera);
    b.expandByPoint(new THREE.Vector2(q.x, q.y));
  }
  return [b.min.x, b.min.y, b.max.x, b.max.y].map((v) => v.toFixed(4)).join(',');
}
// Updated when the view changes (setView, resize, focusOn, the controls' 'change', the
// orthographic switch), not every frame.
function updateProbe() {
  camera.updateMatrixWorld();  // the render has not run yet: project with the camera as it is now
  const probe = document.getElementById('probe');
  const block = new THREE.Box3().setFromPoints([worldOfBlock(0, 0, 0), worldOfBlock(W, D, H)]);
  probe.dataset.ndcBlock = ndcBounds(block.min, block.max);
  if (partBox) probe.dataset.ndcPart = ndcBounds(partBox.min, partBox.max);
  probe.dataset.targetMm = blockOfWorld(controls.target).map((v) => v.toFixed(2)).join(',');
}

// ---- the wood inside: three 3-D textures (one per cut axis, colour for that normal) ----------
function loadVolume(vol) {
  return new Promise((resolve, reject) => {
    const img = new Image();
    // an image the browser cannot read left the page "loading" for ever
    img.onerror = () => reject(new Error('this browser cannot read the colour volumes (lossless '
                                         + 'WebP: Chrome 32+, Firefox 65+, Safari 14+ on macOS 11+ or iOS 14+)'));
    img.onload = () => {
      const c = document.createElement('canvas');
      c.width = img.width; c.height = img.height;
      const g = c.getContext('2d');
      g.drawImage(img, 0, 0);
      const px = g.getImageData(0, 0, img.width, img.height).data;
      const [nx, ny, nz] = vol.shape;  // x fastest; tiles of z slices, vol.tiles across
      const out = new Uint8Array(nx * ny * nz * 4);
      for (let k = 0; k < nz; k++) {
        const tx = (k % vol.tiles) * nx, ty = Math.floor(k / vol.tiles) * ny;
        for (let j = 0; j < ny; j++) {
          const src = ((ty + j) * img.width + tx) * 4, dst = (k * ny + j) * nx * 4;
          out.set(px.subarray(src, src + nx * 4), dst);
        }
      }
      const tex = new THREE.Data3DTexture(out, nx, ny, nz);
      tex.format = THREE.RGBAFormat;
      tex.minFilter = tex.magFilter = THREE.LinearFilter;
      tex.wrapS = tex.wrapT = tex.wrapR = THREE.ClampToEdgeWrapping;
      tex.unpackAlignment = 1;
      tex.needsUpdate = true;
      resolve(tex);
    };
    img.src = vol.image;
  });
}

const capVertex = `
  out vec3 vBlock;
  void main() {
    vec4 w = modelMatrix * vec4(position, 1.0);
    vBlock = vec3(w.x * 1000.0, -w.z * 1000.0, w.y * 1000.0);
    gl_Position = projectionMatrix * viewMatrix * w;
  }`;
// Texel centres sit at (i + 0.5) * cell: the texture coordinate of block point p is p / size.
const capFragment = `
  precision highp sampler3D;
  uniform sampler3D wood;
  uniform vec3 size;
  in vec3 vBlock;
  out vec4 colour;
  void main() { colour = vec4(texture(wood, clamp(vBlock / size, 0.0, 1.0)).rgb, 1.0); }`;

// #cut=AXIS:MM sets the cut, MM clamped to the block; a bare axis, or an MM that is not a
// number, cuts through the middle of that axis. #cut=off starts without one; anything else
// (an unknown axis) gives the default, y through the middle.
const LIMITS = { x: W, y: D, z: H };
const cutArg = (params.get('cut') || '').split(':');
const cutAxis = Object.hasOwn(LIMITS, cutArg[0]) ? cutArg[0] : 'y';  // #cut=toString:5 was NaN
const cutMm = cutAxis === cutArg[0] && cutArg.length > 1 ? parseFloat(cutArg[1]) : NaN;
const cut = { axis: cutAxis,
              pos: Number.isFinite(cutMm) ? THREE.MathUtils.clamp(cutMm, 0, LIMITS[cutAxis])
                : LIMITS[cutAxis] / 2,
              on: cutArg[0] !== 'off',
              // asked: the hash named the cut (#cut=...) or the user ticked or unticked it. Until
              // then the top view shows the part's outside uncut, as 'woodcam preview --camera
              // top' does (woodcam.view.camera.UNCUT_CAMERAS): looking down, the default y cut
              // hid the front half of the part, and a tray's pockets; the other views cut.
              asked: params.has('cut') };
const plane = new THREE.Plane();
let capMesh = null, textures = {}, part = null;
// the hotspot markers and their list items: a marker on the side cut away is hidden with it (it
// floated in the air where the part is cut away, drawn through everything)
const spots = [];
const stencilGroup = new THREE.Group();
scene.add(stencilGroup);

// Turn the cut on or off, its checkbox with it (the views and a hotspot's click turn it).
function setCutOn(on) {
  cut.on = on;
  const box = document.getElementById('cut-on');
  if (box) box.checked = on;
  updatePlane();
}

function updatePlane() {
  // keep the block side beyond the cut (larger coordinate) visible; the normal of the cap
  // faces the viewer (towards smaller coordinates)
  const n = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, -1] }[cut.axis];
  const p = { x: [cut.pos, 0, 0], y: [0, cut.pos, 0], z: [0, 0, cut.pos] }[cut.axis];
  const nw = worldOfBlock(...n).normalize();
  plane.setFromNormalAndCoplanarPoint(nw, worldOfBlock(...p));
  if (capMesh) {
    capMesh.material.uniforms.wood.value = textures[cut.axis];
    capMesh.position.copy(worldOfBlock(...p));
    capMesh.lookAt(capMesh.position.clone().sub(nw));
    capMesh.visible = cut.on;
  }
  if (part) part.traverse((o) => { if (o.material) o.material.clippingPlanes = cut.on ? [plane] : []; });
  stencilGroup.visible = cut.on;
  for (const { marker, li } of spots) {
    const away = cut.on && plane.distanceToPoint(marker.position) < -1e-6;
    marker.visible = !away;
    li.title = away ? 'on the side cut away (hidden); click: look at it, the cut turned off'
      : 'click: look at it';
  }
  document.getElementById('probe').dataset.hotspotsShown = String(spots.filter((s) => s.marker.visible).length);
}

function buildCap() {
  const size = Math.hypot(W, D, H) * 2 / 1000;
  const mat = new THREE.ShaderMaterial({
    glslVersion: THREE.GLSL3, vertexShader: capVertex, fragmentShader: capFragment,
    uniforms: { wood: { value: null }, size: { value: new THREE.Vector3(W, D, H) } },
    stencilWrite: true, stencilRef: 0, stencilFunc: THREE.NotEqualStencilFunc,
    stencilFail: THREE.ReplaceStencilOp, stencilZFail: THREE.ReplaceStencilOp,
    stencilZPass: THREE.ReplaceStencilOp, side: THREE.DoubleSide,
  });
  capMesh = new THREE.Mesh(new THREE.PlaneGeometry(size, size), mat);
  capMesh.renderOrder = 2;
  capMesh.onAfterRender = (r) => r.clearStencil();
  scene.add(capMesh);
}

// three.js' stencil capping: back faces add, front faces subtract, so the stencil is non-zero
// exactly where the cut plane lies inside the closed part.
function stencilFor(geometry, matrixWorld) {
  const base = { depthWrite: false, depthTest: false, colorWrite: false, stencilWrite: true,
                 stencilFunc: THREE.AlwaysStencilFunc, clippingPlanes: [plane] };
  const back = new THREE.MeshBasicMaterial({ ...base, side: THREE.BackSide,
    stencilFail: THREE.IncrementWrapStencilOp, stencilZFail: THREE.IncrementWrapStencilOp,
    stencilZPass: THREE.IncrementWrapStencilOp });
  const front = new THREE.MeshBasicMaterial({ ...base, side: THREE.FrontSide,
    stencilFail: THREE.DecrementWrapStencilOp, stencilZFail: THREE.DecrementWrapStencilOp,
    stencilZPass: THREE.DecrementWrapStencilOp });
  for (const m of [back, front]) {
    const mesh = new THREE.Mesh(geometry, m);
    mesh.matrixAutoUpdate = false;
    mesh.matrix.copy(matrixWorld);
    mesh.renderOrder = 1;
    stencilGroup.add(mesh);
  }
}

// ---- the block frame: arrows along x, y, z from the block's origin, drawn over everything ----
function label(text, colour) {
  const c = document.createElement('canvas');
  c.width = c.height = 64;
  const g = c.getContext('2d');
  g.font = 'bold 48px sans-serif'; g.textAlign = 'center'; g.textBaseline = 'middle';
  g.fillStyle = colour; g.fillText(text, 32, 34);
  const s = new THREE.Sprite(new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(c), depthTest: false }));
  s.renderOrder = 4;
  return s;
}
function addAxes() {
  const len = 0.3 * Math.max(W, D, H), origin = worldOfBlock(0, 0, 0);
  const axes = new THREE.Group();
  for (const [name, dir, colour] of [['x', [1, 0, 0], '#d02020'], ['y', [0, 1, 0], '#20a020'],
                                     ['z', [0, 0, 1], '#2040e0']]) {
    const d = worldOfBlock(...dir).normalize();
    const arrow = new THREE.ArrowHelper(d, origin, len / 1000, new THREE.Color(colour).getHex(),
                                        0.15 * len / 1000, 0.08 * len / 1000);
    arrow.traverse((o) => { if (o.material) o.material.depthTest = false; o.renderOrder = 4; });
    axes.add(arrow);
    const tag = label(name, colour);
    tag.position.copy(origin).addScaledVector(d, 1.12 * len / 1000);
    tag.scale.setScalar(0.12 * len / 1000);
    axes.add(tag);
  }
  scene.add(axes);
  document.getElementById('probe').dataset.axes = 'x,y,z';
}

// ---- measurement and hotspots --------------------------------------------------------------
const raycaster = new THREE.Raycaster();
const picks = [];
const marks = new THREE.Group();
scene.add(marks);
// Whether world point p lies inside the closed part: a ray from p crosses its surface an odd
// number of times (front and back faces both count; the direction is skewed so it grazes no
// axis-aligned face). The same rule as the stencil that draws the cap.
const ODD_RAY = new THREE.Vector3(0.31, 0.53, 0.79).normalize();
function insidePart(p) {
  const sides = [];
  part.traverse((o) => {
    for (const m of o.isMesh ? [].concat(o.material) : []) { sides.push([m, m.side]); m.side = THREE.DoubleSide; }
  });
  const hits = new THREE.Raycaster(p, ODD_RAY).intersectObject(part, true);
  for (const [m, side] of sides) m.side = side;
  return hits.length % 2 === 1;
}
function onClick(ev) {
  if (!part || !document.getElementById('measure').checked) return;
  const r = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1,
                                -((ev.clientY - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  let hit = raycaster.intersectObject(part, true).find((h) => !cut.on || plane.distanceToPoint(h.point) >= 0);
  if (cut.on) {
    // the cut face (the cap) is no part of the GLB: a click on it picks the point of the plane,
    // where the plane lies inside the part and nothing kept is nearer
    const p = raycaster.ray.intersectPlane(plane, new THREE.Vector3());
    if (p && insidePart(p) && (!hit || raycaster.ray.origin.distanceTo(p) < hit.distance)) hit = { point: p };
  }
  if (!hit) return;
  picks.push(hit.point.clone());
  const dot = new THREE.Mesh(new THREE.SphereGeometry(span / 150), new THREE.MeshBasicMaterial({ color: 0xd01010 }));
  dot.position.copy(hit.point);
  marks.add(dot);
  if (picks.length === 2) {
    const mm = picks[0].distanceTo(picks[1]) * 1000;
    const [a, b] = picks.map(blockOfWorld);
    document.getElementById('measurement').textContent =
      `${mm.toFixed(2)} mm between (${a.map((v) => v.toFixed(1)).join(', ')}) and ` +
      `(${b.map((v) => v.toFixed(1)).join(', ')}) mm`;
    marks.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(picks),
                             new THREE.LineBasicMaterial({ color: 0xd01010 })));
    picks.length = 0;
  } else if (marks.children.length > 3) {
    marks.clear();
    marks.add(dot);
  }
}

// Look at a hotspot: the orbit centre moves onto it, seen from the same direction, twice as
// close (orthographic: zoom 2); a cut that hides it (the spot on the side cut away) is turned off.
function focusOn(atMm) {
  const p = worldOfBlock(...atMm);
  const offset = camera.position.clone().sub(controls.target);
  offset.setLength(Math.min(offset.length(), perspDistance(canvasAspect()) / 2));
  controls.target.copy(p);
  camera.position.copy(p).add(offset);
  camera.lookAt(p);
  if (camera === ortho) { ortho.zoom = 2; ortho.updateProjectionMatrix(); }
  if (cut.on && plane.distanceToPoint(p) < -1e-6) {
    cut.asked = true;  // the user's click: the next view keeps the spot in sight
    setCutOn(false);
  }
  updateProbe();
}

function addHotspots() {
  const list = document.getElementById('hotspots');
  for (const h of data.hotspots || []) {
    const m = new THREE.Mesh(new THREE.SphereGeometry(span / 120),
                             new THREE.MeshBasicMaterial({ color: h.kind === 'knot' ? 0x3050ff : 0xff8800,
                                                           depthTest: false }));
    m.position.copy(worldOfBlock(...h.at_mm));
    m.renderOrder = 3;
    scene.add(m);
    const li = document.createElement('li');
    li.textContent = `${h.kind}: ${h.label} at (${h.at_mm.map((v) => v.toFixed(1)).join(', ')}) mm`;
    li.title = 'click: look at it';
    li.onclick = () => {
      for (const other of list.children) other.classList.remove('focused');
      li.classList.add('focused');
      focusOn(h.at_mm);
    };
    list.appendChild(li);
    spots.push({ marker: m, li });
  }
}

// ---- UI ------------------------------------------------------------------------------------
// The printed sheet: the picture on screen and what it shows (the browser's own Print too, by
// 'beforeprint': the canvas itself is not printed).
function snapshot() {
  document.getElementById('snapshot').src = canvas.toDataURL('image/png');
  const measured = document.getElementById('measurement').textContent;
  document.getElementById('sheet-state').textContent =
    `Picture: the view on screen (${camera === ortho ? 'orthographic' : 'perspective'}). Section: ` +
    (cut.on ? `cut at ${cut.axis} = ${cut.pos.toFixed(1)} mm, the part beyond it shown; the cut face ` +
              'shows the wood inside.' : 'none, the whole part.') +
    (measured ? ` Measured: ${measured}.` : '');
}
function bindUi() {
  for (const b of document.querySelectorAll('[data-view]')) b.onclick = () => setView(b.dataset.view);
  const orthoBox = document.getElementById('ortho');
  orthoBox.checked = camera === ortho;  // #ortho
  orthoBox.onchange = () => {
    // the other camera takes over where this one is looking from
    const prev = camera;
    camera = orthoBox.checked ? ortho : persp;
    camera.position.copy(prev.position);
    camera.up.copy(prev.up);
    camera.lookAt(controls.target);
    controls.object = camera;
    updateProbe();
  };
  const axis = document.getElementById('cut-axis'), pos = document.getElementById('cut-pos');
  const on = document.getElementById('cut-on'), label = document.getElementById('cut-label');
  const sync = () => {
    pos.max = LIMITS[cut.axis]; pos.value = cut.pos;
    label.textContent = `${cut.axis} = ${cut.pos.toFixed(1)} mm`;
  };
  axis.value = cut.axis; on.checked = cut.on; sync();
  axis.onchange = () => { cut.axis = axis.value; cut.pos = LIMITS[cut.axis] / 2; sync(); updatePlane(); };
  pos.oninput = () => { cut.pos = parseFloat(pos.value); sync(); updatePlane(); };
  on.onchange = () => { cut.asked = true; cut.on = on.checked; updatePlane(); };
  document.getElementById('print').onclick = () => { snapshot(); window.print(); };
  canvas.addEventListener('click', onClick);
}

async function main() {
  for (const ax of ['x', 'y', 'z']) textures[ax] = await loadVolume(data.volumes[ax]);
  buildCap();
  const glb = Uint8Array.from(atob(document.getElementById('woodcam-glb').textContent.trim()),
                              (c) => c.charCodeAt(0));
  const gltf = await new Promise((ok, fail) => new GLTFLoader().parse(glb.buffer, '', ok, fail));
  part = gltf.scene;
  scene.add(part);
  part.updateMatrixWorld(true);
  part.traverse((o) => { if (o.isMesh) stencilFor(o.geometry, o.matrixWorld); });
  const box = new THREE.Box3().setFromObject(part);
  partBox = box;
  const probe = document.getElementById('probe');
  probe.dataset.bboxMin = box.min.toArray().join(',');
  probe.dataset.bboxMax = box.max.toArray().join(',');
  let normals = 0;
  part.traverse((o) => { if (o.isMesh && o.geometry.attributes.normal) normals += 1; });
  probe.dataset.meshesWithNormals = String(normals);
  addHotspots();
  if (!params.has('bare')) { bindUi(); addAxes(); }
  setView(params.get('view') || 'iso');
  updatePlane();
  window.addEventListener('resize', resize);
  window.addEventListener('beforeprint', snapshot);
  controls.addEventListener('change', updateProbe);  // orbit, pan, zoom, damping
  updateProbe();
  renderer.setAnimationLoop(() => { controls.update(); renderer.render(scene, camera); });
  status.textContent = 'ready';
  document.title = `${data.title}: ready`;
}

main().catch((err) => { status.textContent = `error: ${err}`; document.title = `error: ${err}`; });
