// Loads a glTF/GLB with Babylon.js's glTF loader (NullEngine: no GPU) once per MSFT_lod depth
// (`maxLODsToLoad` 1, 2, ...: Babylon loads the coarsest levels first) and prints, as one JSON
// line, the triangles of the enabled meshes after each load.
const fs = require("fs");
const path = require("path");
const BABYLON = require("babylonjs");
require("babylonjs-loaders");

async function load(data, ext, maxLODsToLoad) {
  const engine = new BABYLON.NullEngine();
  const scene = new BABYLON.Scene(engine);
  const observer = BABYLON.SceneLoader.OnPluginActivatedObservable.add((loader) => {
    if (loader.name === "gltf") loader.extensionOptions = { MSFT_lod: { maxLODsToLoad } };
  });
  await BABYLON.SceneLoader.AppendAsync("", data, scene, undefined, ext);
  BABYLON.SceneLoader.OnPluginActivatedObservable.remove(observer);
  const enabled = scene.meshes
    .filter((m) => m.isEnabled() && m.getTotalIndices() > 0)
    .map((m) => m.getTotalIndices() / 3);
  engine.dispose();
  return enabled;
}

async function main() {
  const file = process.argv[2];
  const depth = Number(process.argv[3]);
  const data = new Uint8Array(fs.readFileSync(file));
  const ext = path.extname(file).toLowerCase();
  const loads = [];
  for (let k = 1; k <= depth; k++) loads.push(await load(data, ext, k));
  console.log(JSON.stringify({ babylon: BABYLON.Engine.Version, loads }));
}
main().catch((e) => {
  console.error(String((e && e.stack) || e));
  process.exit(1);
});
