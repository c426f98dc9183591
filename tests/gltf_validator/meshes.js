// Print each named mesh node of a glTF/GLB as glTF-Transform reads it (with zeux's meshoptimizer
// decoder for EXT_meshopt_compression, KHR_mesh_quantization applied through the node's
// transform): one JSON line {name, positions (world, flat), indices (flat)} per node.  An
// independent reader, for tests that check what bgr writes compressed.
// Usage: node meshes.js FILE   (after `npm install` in this folder)
"use strict";
const { NodeIO } = require("@gltf-transform/core");
const { ALL_EXTENSIONS } = require("@gltf-transform/extensions");
const { MeshoptDecoder } = require("meshoptimizer");

(async () => {
  await MeshoptDecoder.ready;
  const io = new NodeIO()
    .registerExtensions(ALL_EXTENSIONS)
    .registerDependencies({ "meshopt.decoder": MeshoptDecoder });
  const doc = await io.read(process.argv[2]);
  for (const node of doc.getRoot().listNodes()) {
    const mesh = node.getMesh();
    if (!mesh || !node.getName()) continue;
    const m = node.getWorldMatrix(); // column-major 4x4
    const positions = [];
    const indices = [];
    for (const prim of mesh.listPrimitives()) {
      const pos = prim.getAttribute("POSITION");
      const base = positions.length / 3;
      const el = [0, 0, 0];
      for (let i = 0; i < pos.getCount(); i++) {
        pos.getElement(i, el); // normalized integers come back in [0, 1] or [-1, 1]
        const [x, y, z] = el;
        positions.push(
          m[0] * x + m[4] * y + m[8] * z + m[12],
          m[1] * x + m[5] * y + m[9] * z + m[13],
          m[2] * x + m[6] * y + m[10] * z + m[14],
        );
      }
      const idx = prim.getIndices();
      for (let i = 0; i < idx.getCount(); i++) indices.push(base + idx.getScalar(i));
    }
    console.log(JSON.stringify({ name: node.getName(), extras: node.getExtras(), positions, indices }));
  }
})().catch((e) => {
  console.error(String(e));
  process.exit(1);
});
