// Write reference.json: MikkTSpace tangents of the meshes in meshes.json by the reference mikktspace.c algorithm,
// as built to WebAssembly in the npm package `mikktspace` (Don McCurdy; the one three.js's
// BufferGeometryUtils.computeMikkTSpaceTangents uses).  See README.md in this folder.
//
//   npm install mikktspace@1.1.1 && node tests/data/mikktspace/make_reference.js
//
// The package takes unindexed triangles (it welds corners itself, by identical position, normal and uv), so each mesh
// is expanded corner by corner; the output is one (x, y, z, w) per corner, little-endian float32, base64.
const fs = require('fs');
const path = require('path');
const { generateTangents } = require('mikktspace');

const here = __dirname;
const meshes = JSON.parse(fs.readFileSync(path.join(here, 'meshes.json'), 'utf8'));
const version = require('mikktspace/package.json').version;

function floats(b64) {
  const bytes = Buffer.from(b64, 'base64');
  return new Float32Array(bytes.buffer, bytes.byteOffset, bytes.length / 4).slice();
}

function ints(b64) {
  const bytes = Buffer.from(b64, 'base64');
  return new Int32Array(bytes.buffer, bytes.byteOffset, bytes.length / 4).slice();
}

function unindexed(values, indices, width) {
  const out = new Float32Array(indices.length * width);
  indices.forEach((v, k) => { for (let c = 0; c < width; c++) out[k * width + c] = values[v * width + c]; });
  return out;
}

const out = { generator: `npm mikktspace ${version}, generateTangents`, tangents: {} };
for (const [name, mesh] of Object.entries(meshes)) {
  const indices = ints(mesh.indices);
  const tangents = generateTangents(unindexed(floats(mesh.positions), indices, 3),
                                    unindexed(floats(mesh.normals), indices, 3),
                                    unindexed(floats(mesh.uvs), indices, 2));
  out.tangents[name] = Buffer.from(tangents.buffer, tangents.byteOffset, tangents.byteLength).toString('base64');
}
fs.writeFileSync(path.join(here, 'reference.json'), JSON.stringify(out, null, 1) + '\n');
