// phiq animate's spatial view: the mechanism in WebGL with three.js (r111, Debian's libjs-three, inlined) and its
// orbit controls, z up. The sketch's lines are one instanced mesh of boxes (a box along x, scaled to each line's
// length and turned onto it), its joints one instanced mesh of balls, the ground a grid under the mechanism and the
// axes at the origin: a pose costs one matrix per line and per joint and a few buffer uploads, however many loops;
// a large mechanism is drawn as segments and dots (lines(), joints() below).
// Colours as in the .glb: links orange, bodies' arms blue, joints grey, ground pivots black. The parts: one
// instanced mesh per shape of each distinct geometry (10^4 alike parts: one draw call per shape), posed each frame;
// their frames (a checkbox) one set of segments; the part under the pointer named with its pose (phiq.pick).
'use strict';

(function () {
  const d = phiq.data, P = d.points;
  const host = document.getElementById('gl');
  const width = host.clientWidth, height = host.clientHeight;
  // A large mechanism (over 3000 lines and joints) is drawn light: see lines() and joints() below; and without
  // antialiasing, whose multisampling of 10^4 lines costs software WebGL whole frames.
  const large = (d.links.length + d.arms.length) / 2 + d.joints.p.length > 3000;
  const renderer = new THREE.WebGLRenderer({antialias: !large, preserveDrawingBuffer: true});
  renderer.setPixelRatio(1);  // the same pixels on every screen: screenshots compare with references
  renderer.setSize(width, height);
  host.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);

  // extent of everything drawn; a thickness for the shapes from it, as the .glb takes 0.04 of the length scale
  const lo = new THREE.Vector3(...d.lo), hi = new THREE.Vector3(...d.hi);
  const centre = lo.clone().add(hi).multiplyScalar(0.5), size = Math.max(hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 1e-9);
  const w = 0.02 * size;

  const camera = new THREE.PerspectiveCamera(30, width / height, size / 100, size * 100);
  camera.up.set(0, 0, 1);
  camera.position.copy(centre).add(new THREE.Vector3(1, 1, 0.8).normalize().multiplyScalar(2.3 * size));
  camera.lookAt(centre);
  scene.add(new THREE.AmbientLight(0xffffff, 0.55));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.set(1, 0.5, 2);
  scene.add(sun);

  // the ground: a grid just under the lowest point; the axes from the origin
  const grid = new THREE.GridHelper(2 * size, 20, 0xbbbbbb, 0xe4e4e4);
  grid.rotation.x = Math.PI / 2;
  grid.position.set(centre.x, centre.y, lo.z - 0.05 * size);  // below: no line of the mechanism lies in it
  scene.add(grid);
  const axes = new THREE.AxesHelper(d.axis_length || 0.3 * size);
  scene.add(axes);

  // Solid shapes (instanced boxes and balls); for a large mechanism, where each would be a few pixels at most and
  // software WebGL would spend seconds a frame on their triangles, one line per link (one draw call of 2 vertices
  // each) and a dot per joint.
  const moving = [], fixed = [];  // the joints' points
  d.joints.p.forEach((p, k) => (d.joints.fixed[k] === '1' ? fixed : moving).push(p));
  const solid = !large;
  const m = new THREE.Matrix4(), q = new THREE.Quaternion(), s = new THREE.Vector3(), x = new THREE.Vector3(1, 0, 0);
  const a = new THREE.Vector3(), c = new THREE.Vector3(), dir = new THREE.Vector3();
  function add(object) {
    object.frustumCulled = false;  // bounds of a unit shape or of the first pose: not where the mechanism goes
    scene.add(object);
    return object;
  }
  // Lines between the point pairs of `list`: boxes along x, scaled to each line's length and turned onto it; or
  // segments. A geometry per instanced mesh: three r111 keeps one instance buffer binding per geometry.
  function lines(list, colour) {
    const n = list.length / 2;
    if (!solid) {
      const xyz = new Float32Array(6 * n), g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
      add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({color: colour})));
      return (pos) => {
        for (let k = 0; k < 2 * n; ++k) for (let i = 0; i < 3; ++i) xyz[3 * k + i] = pos[3 * list[k] + i];
        g.attributes.position.needsUpdate = true;
      };
    }
    const box = new THREE.BoxBufferGeometry(1, w, w);
    box.translate(0.5, 0, 0);
    const mesh = add(new THREE.InstancedMesh(box, new THREE.MeshLambertMaterial({color: colour}), Math.max(1, n)));
    mesh.count = n;
    return (pos) => {
      for (let k = 0; k < n; ++k) {
        a.fromArray(pos, 3 * list[2 * k]), c.fromArray(pos, 3 * list[2 * k + 1]);
        dir.subVectors(c, a);
        const len = dir.length();
        if (len > 0) q.setFromUnitVectors(x, dir.divideScalar(len)); else q.set(0, 0, 0, 1);
        m.compose(a, q, s.set(Math.max(len, 1e-12), 1, 1));
        mesh.setMatrixAt(k, m);
      }
      mesh.instanceMatrix.needsUpdate = true;
    };
  }
  // Joints at the points of `list`: balls, or dots of 4 pixels.
  function joints(list, colour) {
    if (!solid) {
      const xyz = new Float32Array(3 * list.length), g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
      add(new THREE.Points(g, new THREE.PointsMaterial({color: colour, size: 4, sizeAttenuation: false})));
      return (pos) => {
        list.forEach((p, k) => { for (let i = 0; i < 3; ++i) xyz[3 * k + i] = pos[3 * p + i]; });
        g.attributes.position.needsUpdate = true;
      };
    }
    const mesh = add(new THREE.InstancedMesh(new THREE.SphereBufferGeometry(0.75 * w, 12, 8),
                                             new THREE.MeshLambertMaterial({color: colour}), Math.max(1, list.length)));
    mesh.count = list.length;
    return (pos) => {
      list.forEach((p, k) => mesh.setMatrixAt(k, m.makeTranslation(pos[3 * p], pos[3 * p + 1], pos[3 * p + 2])));
      mesh.instanceMatrix.needsUpdate = true;
    };
  }
  const placeLinks = lines(d.links, 0xe6801a), placeArms = lines(d.arms, 0x4573b3);
  const placeJoints = joints(moving, 0x404040), placeGround = joints(fixed, 0x0d0d0d);

  // ---- the parts
  const parts = phiq.parts, N = parts.names.length;
  const bytes = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0)).buffer;
  const members = parts.geometries.map(() => []), slot = new Int32Array(N);
  parts.geometry.forEach((g, k) => { slot[k] = members[g].length; members[g].push(k); });
  const partMeshes = parts.geometries.map((shapes, g) => shapes.map((sh) => {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(bytes(sh.p)), 3));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(sh.i)), 1));
    geometry.computeVertexNormals();  // the vertices are split at edges: smooth where curved, sharp at edges
    const mesh = add(new THREE.InstancedMesh(geometry, new THREE.MeshLambertMaterial({color: sh.colour}), members[g].length));
    mesh.userData.parts = members[g];
    return mesh;
  }));
  const pickable = [].concat(...partMeshes);
  // output.clearance: a red copy, a little larger, of each part of a pair, shown while the pair is within the
  // threshold; the witness points at each pair's worst pose, red dots joined by a line
  const nearMaterial = new THREE.MeshLambertMaterial({color: 0xd62728}), nearMeshes = [];
  const grown = new THREE.Vector3(1.02, 1.02, 1.02);
  if (phiq.clearance) {
    const inPairs = new Set();
    for (const pair of phiq.clearance.pairs) inPairs.add(pair.a), inPairs.add(pair.b);
    for (const k of inPairs)
      for (const mesh of partMeshes[parts.geometry[k]]) {
        const copy = add(new THREE.Mesh(mesh.geometry, nearMaterial));
        copy.matrixAutoUpdate = false, copy.visible = false, copy.userData.part = k;
        nearMeshes.push(copy);
      }
    const ends = [];
    for (const pair of phiq.clearance.pairs) ends.push(...pair.point_a, ...pair.point_b);
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(ends), 3));
    add(new THREE.LineSegments(g, new THREE.LineBasicMaterial({color: 0xd62728})));
    add(new THREE.Points(g, new THREE.PointsMaterial({color: 0xd62728, size: 8, sizeAttenuation: false})));
  }
  const frameXyz = new Float32Array(18 * N), frameRgb = new Float32Array(18 * N);
  for (let k = 0; k < N; ++k)
    for (let a = 0; a < 3; ++a) for (let e = 0; e < 2; ++e) frameRgb[18 * k + 6 * a + 3 * e + a] = 0.85;
  const frameGeometry = new THREE.BufferGeometry();
  frameGeometry.setAttribute('position', new THREE.BufferAttribute(frameXyz, 3));
  frameGeometry.setAttribute('color', new THREE.BufferAttribute(frameRgb, 3));
  const partAxes = add(new THREE.LineSegments(frameGeometry, new THREE.LineBasicMaterial({vertexColors: THREE.VertexColors})));
  const unit = new THREE.Vector3(1, 1, 1), axis = new THREE.Vector3(), origin = new THREE.Vector3();
  function placeParts(place, frames, near) {
    for (const copy of nearMeshes) {
      const k = copy.userData.part;
      copy.visible = !!near[k];
      if (copy.visible) copy.matrix.compose(origin.fromArray(place, 7 * k), q.fromArray(place, 7 * k + 3), grown);
    }
    for (let k = 0; k < N; ++k) {
      origin.fromArray(place, 7 * k);
      q.fromArray(place, 7 * k + 3);
      m.compose(origin, q, unit);
      for (const mesh of partMeshes[parts.geometry[k]]) mesh.setMatrixAt(slot[k], m);
      if (frames)
        for (let a = 0; a < 3; ++a) {
          axis.set(a === 0 ? 1 : 0, a === 1 ? 1 : 0, a === 2 ? 1 : 0).applyQuaternion(q).multiplyScalar(0.15 * size);
          origin.toArray(frameXyz, 18 * k + 6 * a);
          axis.add(origin).toArray(frameXyz, 18 * k + 6 * a + 3);
        }
    }
    for (const mesh of pickable) mesh.instanceMatrix.needsUpdate = true;
    partAxes.visible = frames;
    frameGeometry.attributes.position.needsUpdate = true;
  }
  const ray = new THREE.Raycaster(), pointer = new THREE.Vector2();
  function partAt(event) {
    const r = renderer.domElement.getBoundingClientRect();
    pointer.set((event.clientX - r.left) / r.width * 2 - 1, 1 - (event.clientY - r.top) / r.height * 2);
    ray.setFromCamera(pointer, camera);
    const hit = ray.intersectObjects(pickable)[0];
    return hit && hit.instanceId !== undefined ? hit.object.userData.parts[hit.instanceId] : -1;
  }
  if (N) {
    renderer.domElement.addEventListener('mousemove', (e) => phiq.pick(partAt(e)));
    renderer.domElement.addEventListener('click', (e) => phiq.pick(partAt(e)));
  }

  const trails = phiq.traces.map((tr) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(tr.pos, 3));
    g.setDrawRange(0, 0);
    const line = new THREE.Line(g, new THREE.LineBasicMaterial({color: tr.colour}));
    line.frustumCulled = false;
    scene.add(line);
    return line;
  });
  const vecPos = new Float32Array(6 * P);
  const vecGeometry = new THREE.BufferGeometry();
  vecGeometry.setAttribute('position', new THREE.BufferAttribute(vecPos, 3));
  const vectors = new THREE.LineSegments(vecGeometry, new THREE.LineBasicMaterial({color: 0xcc00cc}));
  vectors.frustumCulled = false;
  scene.add(vectors);
  // forces (phiq animate --forces): reactions orange, efforts red, a force from its point, a moment along its axis
  const F = d.forces || {scale: 0, arrows: []};
  const forcePos = new Float32Array(12 * F.arrows.length), forceColour = new Float32Array(12 * F.arrows.length);
  const forceGeometry = new THREE.BufferGeometry();
  forceGeometry.setAttribute('position', new THREE.BufferAttribute(forcePos, 3));
  forceGeometry.setAttribute('color', new THREE.BufferAttribute(forceColour, 3));
  const forceLines = new THREE.LineSegments(forceGeometry, new THREE.LineBasicMaterial({vertexColors: THREE.VertexColors}));
  forceLines.frustumCulled = false;
  scene.add(forceLines);
  function placeForces(frame, show) {
    let n = 0;
    if (show)
      for (const a of F.arrows) {
        const rgb = a.kind === 'effort' ? [0.84, 0.15, 0.16] : [1.0, 0.5, 0.05];
        for (const v of [a.force, a.moment]) {
          if (v[3 * frame] === null) continue;
          for (let k = 0; k < 3; ++k) {
            forcePos[6 * n + k] = a.at[3 * frame + k];
            forcePos[6 * n + 3 + k] = a.at[3 * frame + k] + F.scale * v[3 * frame + k];
            forceColour[6 * n + k] = forceColour[6 * n + 3 + k] = rgb[k];
          }
          ++n;
        }
      }
    forceGeometry.setDrawRange(0, 2 * n);
    forceGeometry.attributes.position.needsUpdate = forceGeometry.attributes.color.needsUpdate = true;
  }
  const legend = document.createElement('div');
  legend.className = 'legend';
  phiq.traces.forEach((tr) => {
    const line = document.createElement('div');
    line.style.color = tr.colour;
    line.textContent = tr.name;
    legend.appendChild(line);
  });
  host.appendChild(legend);

  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(centre);
  controls.update();
  controls.addEventListener('change', () => renderer.render(scene, camera));

  let groundPlaced = false;  // the ground pivots: placed once, at the first pose drawn
  const vscale = d.vmax > 0 ? 0.25 * size / d.vmax : 0;

  phiq.start({
    draw(p, show) {
      placeParts(p.parts, show.frames, p.near);
      placeLinks(p.pos), placeArms(p.pos), placeJoints(p.pos);
      if (!groundPlaced) placeGround(p.pos), groundPlaced = true;
      trails.forEach((line) => line.geometry.setDrawRange(0, show.trails ? p.samples : 0));
      let n = 0;
      if (show.vectors && p.vel)
        for (let i = 0; i < P; ++i) {
          if (d.moving[i] !== '1') continue;
          for (let k = 0; k < 3; ++k) {
            vecPos[6 * n + k] = p.pos[3 * i + k];
            vecPos[6 * n + 3 + k] = p.pos[3 * i + k] + vscale * p.vel[3 * i + k];
          }
          ++n;
        }
      vecGeometry.setDrawRange(0, 2 * n);
      vecGeometry.attributes.position.needsUpdate = true;
      placeForces(p.frame, show.forces);
      renderer.render(scene, camera);
    },
    screenPoints(pos) {
      const r = renderer.domElement.getBoundingClientRect(), v = new THREE.Vector3(), out = [];
      for (let i = 0; i < P; ++i) {
        v.fromArray(pos, 3 * i).project(camera);
        out.push({x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height, moving: d.moving[i] === '1'});
      }
      return out;
    },
  });
})();
