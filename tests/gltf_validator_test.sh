#!/bin/sh
# ctest gltf_validator: `phiq animate` on a planar reference-point four-bar, a natural-coordinate one, the
# spatial RSSR, the Cardan joint (its parts: meshes, one material per colour) and the four-bar knee's clearance
# witness points (nodes with extras, animated translation and scale), each .glb checked by the Khronos
# glTF-Validator (npm package gltf-validator, installed by tools/install_deps.sh into tools/gltf_validator/; nothing
# is downloaded here): no error, and the validator's warnings and infos listed. Skipped (exit 77) when node or the validator is absent.
# Usage: gltf_validator_test.sh PHIQ MODELS_DIR VALIDATOR_DIR WORK_DIR
set -u
phiq="$1"; models="$2"; work="$4"
validator="$(cd "$3" 2>/dev/null && pwd)/node_modules/gltf-validator"  # absolute: node resolves it so
command -v node >/dev/null 2>&1 || { echo "gltf_validator: node not found (tools/install_deps.sh installs it): skipped"; exit 77; }
[ -f "$validator/package.json" ] || { echo "gltf_validator: $validator absent (tools/install_deps.sh installs it): skipped"; exit 77; }
rm -rf "$work" && mkdir -p "$work" || exit 1
check='
    const fs = require("fs");
    const validator = require(process.argv[1]);
    const file = process.argv[2];
    validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {maxIssues: 0}).then((report) => {
      const i = report.issues;
      console.log(file + ": " + i.numErrors + " errors, " + i.numWarnings + " warnings, " + i.numInfos + " infos");
      for (const m of i.messages) console.log("  " + ["error", "warning", "info", "hint"][m.severity] + " " + m.code + " " + m.pointer + ": " + m.message);
      process.exit(i.numErrors === 0 && report.info.animationCount === 1 ? 0 : 1);
    }, (e) => { console.log(file + ": " + e); process.exit(1); });
  '
status=0
for m in seed/fourbar_reference_point seed/fourbar_natural spatial/rssr spatial/cardan; do
  name=$(basename "$m")
  "$phiq" run -q "$models/$m.yaml" -o "$work/$name.csv" || { echo "gltf_validator: phiq run $m failed"; exit 1; }
  "$phiq" animate "$models/$m.yaml" "$work/$name.csv" -o "$work/$name.glb" || { echo "gltf_validator: phiq animate $m failed"; exit 1; }
  node -e "$check" "$validator" "$work/$name.glb" || status=1
done
# output.clearance: the witness points' nodes (each with its extras) validate too
"$phiq" animate "$models/clearance/fourbar_knee.yaml" -o "$work/knee.glb" || { echo "gltf_validator: phiq animate fourbar_knee failed"; exit 1; }
[ "$(grep -a -o '"clearance":{' "$work/knee.glb" | wc -l)" -ge 2 ] || { echo "gltf_validator: knee.glb has no clearance witness nodes"; status=1; }
node -e "$check" "$validator" "$work/knee.glb" || status=1
exit $status
