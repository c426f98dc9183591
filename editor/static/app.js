// bgr serve's page: the derived model in three.js, re-loaded when the server says a new one is
// derived (a websocket), the camera kept; the error of a failed derivation beside the last good
// model; an inspector whose settings the server derives again.
import * as THREE from "/static/vendor/three.bundle.min.js";
import { GLTFLoader, OrbitControls } from "/static/vendor/three.bundle.min.js";

const view = document.getElementById("view");
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf2f2f2);
scene.add(new THREE.HemisphereLight(0xffffff, 0x888877, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(0.5, 1, 0.8);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 20000);
camera.position.set(40, 30, 40);
const controls = new OrbitControls(camera, renderer.domElement);
const loader = new GLTFLoader();
let model = null; // the scene of the model shown
let framed = false; // the camera was fitted to the first model; later models keep it

function resize() {
  const { clientWidth: w, clientHeight: h } = view;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener("resize", resize);
resize();
renderer.setAnimationLoop(() => {
  controls.update();
  renderer.render(scene, camera);
});

function frame(object) {
  const box = new THREE.Box3().setFromObject(object);
  if (box.isEmpty()) return;
  const size = box.getSize(new THREE.Vector3()).length();
  const centre = box.getCenter(new THREE.Vector3());
  camera.near = size / 1000;
  camera.far = size * 20;
  camera.position.copy(centre).add(new THREE.Vector3(0.9, 0.7, 1.1).multiplyScalar(size * 0.95));
  camera.updateProjectionMatrix();
  controls.target.copy(centre);
}

async function showModel(message, data) {
  const gltf = await loader.parseAsync(data, "");
  if (model) {
    scene.remove(model);
    model.traverse((o) => {
      if (o.geometry) o.geometry.dispose();
      if (o.material) [].concat(o.material).forEach((m) => m.dispose());
    });
  }
  model = gltf.scene;
  scene.add(model);
  if (!framed) {
    frame(model);
    framed = true;
  }
  document.getElementById("error").hidden = true;
  const warnings = message.warnings.length ? `, ${message.warnings.length} warnings` : "";
  setStatus(
    `${message.terminals.toLocaleString()} terminals, ${message.triangles.toLocaleString()} ` +
      `triangles in ${message.seconds} s${warnings}`
  );
  document.body.dataset.version = String(message.version);
  document.body.dataset.state = "model";
}

function showErrors(errors) {
  const lines = errors.map((e) => {
    const file = e.path ? e.path.split(/[\\/]/).pop() : "";
    const where = file ? `${file}:${e.line}:${e.column}: ` : "";
    let text = `${where}error:\n${e.message}`;
    if (e.source) {
      // the part of the line around the column, so that the caret stays in the panel
      const from = Math.max(e.column - 24, 0);
      const shown = (from ? "…" : "") + e.source.slice(from, from + 40);
      const at = e.column - 1 - from + (from ? 1 : 0);
      const caret = " ".repeat(Math.max(at, 0)) + "^".repeat(Math.max(e.length || 1, 1));
      text += `\n  ${e.line} | ${shown}\n  ${" ".repeat(String(e.line).length)} | ${caret}`;
    }
    if (e.hint) text += `\nhint: ${e.hint}`;
    return text;
  });
  document.getElementById("error-text").textContent = lines.join("\n\n");
  document.getElementById("error").hidden = false;
  document.body.dataset.state = "error";
  setStatus(model ? "error: the last good model is shown" : "error");
}

function setStatus(text) {
  document.getElementById("status").textContent = text;
}

// ---- the server's messages -----------------------------------------------------------------

function connect() {
  const socket = new WebSocket(`ws://${location.host}/ws`);
  socket.binaryType = "arraybuffer";
  let announced = null; // a model message: its GLB comes next, as bytes
  socket.onmessage = (event) => {
    if (typeof event.data !== "string") {
      if (announced) showModel(announced, event.data);
      announced = null;
      return;
    }
    const message = JSON.parse(event.data);
    if (message.type === "model") announced = message;
    else if (message.type === "error") showErrors(message.errors);
  };
  socket.onclose = () => setTimeout(connect, 1000); // the server restarted: come back
}

// ---- the inspector -------------------------------------------------------------------------

let settings = { seed: 0, attrs: {}, feature: null };
let sending = null;

function send() {
  clearTimeout(sending);
  sending = setTimeout(() => {
    fetch("/settings", {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify(settings),
    });
  }, 120);
}

function attrInput(name, info, value) {
  const row = document.createElement("label");
  row.className = "row";
  row.textContent = info.displayName ? info.displayName[0] : name;
  const set = (v) => {
    settings.attrs[name] = v;
    send();
  };
  const current = value !== undefined ? value : info.default;
  let input;
  if (info.enum && info.enum.values) {
    input = document.createElement("select");
    for (const v of info.enum.values) input.add(new Option(String(v), String(v)));
    input.value = String(current);
    input.onchange = () => set(typeof current === "number" ? Number(input.value) : input.value);
  } else if (typeof current === "boolean") {
    input = document.createElement("input");
    input.type = "checkbox";
    input.checked = current;
    input.onchange = () => set(input.checked);
  } else if (typeof current === "number") {
    const range = info.range || {};
    const span = Math.max(Math.abs(current), 1);
    input = document.createElement("input");
    input.type = "range";
    input.min = range.min ?? Math.min(0, current - span);
    input.max = range.max ?? current + span * 2;
    input.step = range.stepsize ?? (Number.isInteger(current) ? 1 : "any");
    input.value = current;
    const shown = document.createElement("output");
    shown.textContent = current;
    input.oninput = () => {
      shown.textContent = input.value;
      set(Number(input.value));
    };
    row.append(input, shown);
    input.name = name;
    return row;
  } else {
    input = document.createElement("input");
    input.value = current ?? "";
    input.onchange = () => set(input.value);
  }
  input.name = name;
  row.append(input);
  return row;
}

async function loadState() {
  const state = await (await fetch("/state")).json();
  document.getElementById("file").textContent = state.file;
  document.title = `${state.file}: bgr serve`;
  settings = { seed: state.seed, attrs: { ...state.values }, feature: state.feature };
  const seed = document.getElementById("seed");
  seed.value = state.seed;
  seed.onchange = () => {
    settings.seed = Number(seed.value) || 0;
    send();
  };
  const attrs = document.getElementById("attrs");
  attrs.replaceChildren();
  for (const [name, info] of Object.entries(state.attrs)) {
    if (info.hidden) continue;
    attrs.append(attrInput(name, info, state.values[name]));
  }
  if (state.features.length) {
    const lot = document.getElementById("lot");
    lot.replaceChildren(new Option("all footprints", ""));
    state.features.forEach((name, i) => lot.add(new Option(name, String(i))));
    lot.value = state.feature === null ? "" : String(state.feature);
    lot.onchange = () => {
      settings.feature = lot.value === "" ? null : Number(lot.value);
      send();
    };
    document.getElementById("lot-row").hidden = false;
  }
  if (state.errors.length) showErrors(state.errors);
}

document.getElementById("command-button").onclick = async () => {
  const { command } = await (await fetch("/command")).json();
  const box = document.getElementById("command");
  box.textContent = command;
  box.hidden = false;
  if (navigator.clipboard) navigator.clipboard.writeText(command).catch(() => {});
};

// ---- click to identify ---------------------------------------------------------------------

const raycaster = new THREE.Raycaster();
let down = null;
renderer.domElement.addEventListener("pointerdown", (e) => (down = [e.clientX, e.clientY]));
renderer.domElement.addEventListener("pointerup", async (e) => {
  if (!model || !down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
  const rect = renderer.domElement.getBoundingClientRect();
  const pointer = new THREE.Vector2(
    ((e.clientX - rect.left) / rect.width) * 2 - 1,
    -((e.clientY - rect.top) / rect.height) * 2 + 1
  );
  raycaster.setFromCamera(pointer, camera);
  const hit = raycaster.intersectObject(model, true)[0];
  if (!hit) return;
  // the model's own frame: the file's root node may move it (a site's offset)
  const root = model.children[0] || model;
  const p = root.worldToLocal(hit.point.clone());
  const found = await (await fetch(`/pick?x=${p.x}&y=${p.y}&z=${p.z}`)).json();
  if (!found.found) return;
  const attrs = Object.entries(found.attrs)
    .map(([k, v]) => `${k} = ${v}`)
    .join(", ");
  document.getElementById("picked").textContent =
    `${found.label}\n${found.path}` + (attrs ? `\nattrs: ${attrs}` : "");
});

loadState();
connect();
