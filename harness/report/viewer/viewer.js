// The report's viewer: plays recorded runs of one scene side by side on one time slider, each
// body drawn from the scene's shapes (three.js, inlined before this script as the global THREE),
// contacts that carry force as dots with their force as a line. Data: the JSON of each
// `.cb-viewer` element (harness/report/viewer/payload.py; frames.py says the binary layout).
// Query parameters `view-time=T` (scene time unit) or `view-event=NAME` set the first frame
// shown (the docs' screenshots and the browser test use them).
(function () {
  "use strict";

  async function int16s(base64) {
    const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("gzip"));
    return new Int16Array(await new Response(stream).arrayBuffer());
  }

  // One run's frames from its block: poses (F x nb x 7, stored as differences), contact counts
  // (F), contacts (n x 7: pair, point, force).
  async function decodeRun(run, frames, bodies, quant) {
    const data = await int16s(run.data);
    const stride = bodies * 7;
    const poses = data.subarray(0, frames * stride);
    for (let i = stride; i < poses.length; i++) poses[i] += poses[i - stride];   // wraps at 16 bits
    const counts = data.subarray(frames * stride, frames * stride + frames);
    const table = data.subarray(frames * stride + frames);
    const starts = new Int32Array(frames + 1);
    for (let f = 0; f < frames; f++) starts[f + 1] = starts[f] + counts[f];
    return { poses, counts, table, starts, stride, quant };
  }

  function shapeMesh(shape, material, transparentMaterial) {
    let geometry;
    let chosen = material;
    const k = shape.kind;
    if (k === "sphere") geometry = new THREE.SphereGeometry(shape.radius, 24, 16);
    else if (k === "box") geometry = new THREE.BoxGeometry(2 * shape.half[0], 2 * shape.half[1], 2 * shape.half[2]);
    else if (k === "capsule") {
      geometry = new THREE.CapsuleGeometry(shape.radius, 2 * shape.half_length, 6, 20);
      geometry.rotateX(Math.PI / 2);                   // three's axis y -> the shape's z
    } else if (k === "cylinder") {
      geometry = new THREE.CylinderGeometry(shape.radius, shape.radius, 2 * shape.half_length, 28);
      geometry.rotateX(Math.PI / 2);
      chosen = transparentMaterial;     // a CAD patch the scene extends to a whole cylinder
    } else if (k === "bore") {
      // three's angle theta sits at the shape's angle theta - pi/2 after the turn about x
      geometry = new THREE.CylinderGeometry(shape.radius, shape.radius, 2 * shape.half_length, 40, 1,
        true, shape.start + Math.PI / 2, shape.end - shape.start);
      geometry.rotateX(Math.PI / 2);
      chosen = transparentMaterial;
    } else if (k === "circle" || k === "arc") {
      geometry = new THREE.TorusGeometry(shape.radius, shape.tube, 6, 64, shape.end - shape.start);
      geometry.rotateZ(shape.start);
    } else if (k === "plane" || k === "rectangle") {
      geometry = new THREE.PlaneGeometry(2 * shape.half[0], 2 * shape.half[1]);
      chosen = transparentMaterial;
    } else if (k === "disc") {
      geometry = new THREE.CircleGeometry(shape.radius, 40);
      chosen = transparentMaterial;
    } else {
      return null;
    }
    const mesh = new THREE.Mesh(geometry, chosen);
    mesh.position.set(shape.p[0], shape.p[1], shape.p[2]);
    mesh.quaternion.set(shape.q[1], shape.q[2], shape.q[3], shape.q[0]);
    return mesh;
  }

  // One three.js scene per run; every run's copy of a shape shares its geometry (clone()).
  function buildTemplates(description) {
    return description.bodies.map((body) => {
      const colour = new THREE.Color(body.colour);
      const solid = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide,
        transparent: body.fixed, opacity: body.fixed ? 0.35 : 1.0, depthWrite: !body.fixed });
      const sheer = new THREE.MeshLambertMaterial({ color: colour, side: THREE.DoubleSide,
        transparent: true, opacity: body.fixed ? 0.2 : 0.55, depthWrite: false });
      const group = new THREE.Group();
      for (const shape of body.shapes) {
        const mesh = shapeMesh(shape, solid, sheer);
        if (mesh) group.add(mesh);
      }
      return group;
    });
  }

  function buildRunScene(templates, maxContacts, size) {
    const scene = new THREE.Scene();
    scene.background = new THREE.Color("#ffffff");
    scene.add(new THREE.AmbientLight(0xffffff, 1.4));
    const light = new THREE.DirectionalLight(0xffffff, 1.6);
    light.position.set(1, 2, 3);
    scene.add(light);
    const groups = templates.map((t) => { const g = t.clone(); scene.add(g); return g; });
    const capacity = Math.max(1, maxContacts);
    const dots = new THREE.InstancedMesh(new THREE.SphereGeometry(0.006 * size, 8, 6),
      new THREE.MeshBasicMaterial({ color: 0x000000 }), capacity);
    dots.count = 0;
    dots.frustumCulled = false;
    scene.add(dots);
    const lineGeometry = new THREE.BufferGeometry();
    lineGeometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(capacity * 6), 3));
    lineGeometry.setDrawRange(0, 0);
    const lines = new THREE.LineSegments(lineGeometry, new THREE.LineBasicMaterial({ color: 0xd00000 }));
    lines.frustumCulled = false;
    scene.add(lines);
    return { scene, groups, dots, lines };
  }

  function format(value, digits) {
    return value === null || value === undefined ? "—" : Number(value).toFixed(digits);
  }

  class Viewer {
    constructor(root, payload) {
      this.root = root;
      this.p = payload;
      this.frame = 0;
      this.playing = false;
    }

    async start() {
      const p = this.p;
      this.times = Float64Array.from(p.times);
      this.decoded = await Promise.all(p.runs.map((r) => decodeRun(r, this.times.length,
        p.scene.bodies.length, p.quant)));
      const canvas = this.root.querySelector("canvas");
      this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
      this.renderer.setPixelRatio(window.devicePixelRatio || 1);
      const templates = buildTemplates(p.scene);
      const maxContacts = Math.max(1, ...this.decoded.map((d) => Math.max(0, ...d.counts)));
      this.views = this.decoded.map(() => buildRunScene(templates, maxContacts, p.scene.size));
      const centre = new THREE.Vector3(...p.camera.target);
      this.camera = new THREE.PerspectiveCamera(30, 1, p.scene.size / 100, p.scene.size * 50);
      this.camera.up.set(...p.camera.up);
      this.camera.position.copy(centre).add(new THREE.Vector3(...p.camera.direction)
        .multiplyScalar(p.camera.distance));
      this.controls = new THREE.OrbitControls(this.camera, canvas);
      this.controls.target.copy(centre);
      this.controls.update();
      this.controls.addEventListener("change", () => this.render());
      this.slider = this.root.querySelector(".cb-slider");
      this.slider.max = String(this.times.length - 1);
      this.slider.addEventListener("input", () => this.show(Number(this.slider.value)));
      this.root.querySelector(".cb-play").addEventListener("click", () => this.toggle());
      for (const box of this.root.querySelectorAll("input[type=checkbox]")) {
        box.addEventListener("change", () => this.show(this.frame));
      }
      for (const button of this.root.querySelectorAll(".cb-event")) {
        button.addEventListener("click", () => this.showTime(Number(button.dataset.time)));
      }
      new ResizeObserver(() => this.layout()).observe(this.root);
      this.layout();
      const query = new URLSearchParams(window.location.search);
      const event = p.events.find((e) => e.name === query.get("view-event"));
      if (event) this.showTime(event.time);
      else if (query.has("view-time")) this.showTime(Number(query.get("view-time")));
      else this.show(0);
      this.root.dataset.ready = "true";
    }

    layout() {
      const canvas = this.renderer.domElement;
      const width = this.root.clientWidth;
      if (width < 16) { this.cell = null; return; }      // hidden (a folded or cut page)
      const n = this.views.length;
      this.columns = Math.min(n, width < 700 ? 2 : 3);
      this.rows = Math.ceil(n / this.columns);
      this.cell = { w: Math.floor(width / this.columns), h: Math.floor(0.75 * width / this.columns) };
      this.renderer.setSize(this.cell.w * this.columns, this.cell.h * this.rows, false);
      canvas.style.width = `${this.cell.w * this.columns}px`;
      canvas.style.height = `${this.cell.h * this.rows}px`;
      const stage = this.root.querySelector(".cb-stage");
      stage.style.height = canvas.style.height;
      const titles = this.root.querySelectorAll(".cb-title");
      titles.forEach((title, i) => {
        title.style.left = `${(i % this.columns) * this.cell.w}px`;
        title.style.top = `${Math.floor(i / this.columns) * this.cell.h}px`;
        title.style.width = `${this.cell.w - 8}px`;
      });
      this.render();
    }

    showTime(time) {
      let best = 0;
      for (let i = 0; i < this.times.length; i++) {
        if (Math.abs(this.times[i] - time) < Math.abs(this.times[best] - time)) best = i;
      }
      this.show(best);
    }

    show(frame) {
      this.frame = Math.max(0, Math.min(frame, this.times.length - 1));
      this.slider.value = String(this.frame);
      const p = this.p;
      const showContacts = this.root.querySelector(".cb-contacts").checked;
      const t = this.times[this.frame];
      this.root.querySelector(".cb-time").textContent =
        `t = ${t.toFixed(3)} ${p.scene.time_unit}`;
      const matrix = new THREE.Matrix4();
      const q = new THREE.Quaternion();
      const v = new THREE.Vector3();
      const one = new THREE.Vector3(1, 1, 1);
      this.decoded.forEach((d, r) => {
        const view = this.views[r];
        const step = d.quant.step;
        const c = d.quant.centre;
        const base = this.frame * d.stride;
        view.groups.forEach((group, b) => {
          const o = base + 7 * b;
          group.position.set(c[0] + d.poses[o] * step, c[1] + d.poses[o + 1] * step,
            c[2] + d.poses[o + 2] * step);
          group.quaternion.set(d.poses[o + 4], d.poses[o + 5], d.poses[o + 6], d.poses[o + 3])
            .normalize();
        });
        const start = d.starts[this.frame];
        const count = showContacts ? d.counts[this.frame] : 0;
        const line = view.lines.geometry.attributes.position;
        const reach = 0.12 * p.scene.size;
        for (let i = 0; i < count; i++) {
          const e = 7 * (start + i);
          v.set(c[0] + d.table[e + 1] * step, c[1] + d.table[e + 2] * step, c[2] + d.table[e + 3] * step);
          matrix.compose(v, q.identity(), one);
          view.dots.setMatrixAt(i, matrix);
          const scale = p.force_range / 32767 * reach;         // quantised force -> drawn length
          line.setXYZ(2 * i, v.x, v.y, v.z);
          line.setXYZ(2 * i + 1, v.x + d.table[e + 4] * scale, v.y + d.table[e + 5] * scale,
            v.z + d.table[e + 6] * scale);
        }
        view.dots.count = count;
        view.dots.instanceMatrix.needsUpdate = true;
        line.needsUpdate = true;
        view.lines.geometry.setDrawRange(0, 2 * count);
        const run = p.runs[r];
        const note = this.root.querySelectorAll(".cb-ended")[r];
        note.textContent = t > run.ends + 1e-9
          ? `recording ends at ${run.ends.toFixed(3)} ${p.scene.time_unit} (${run.status}): last pose`
          : "";
      });
      this.root.dataset.frame = String(this.frame);
      this.render();
    }

    render() {
      if (!this.renderer || !this.cell || this.cell.h < 8) return;
      const r = this.renderer;
      const heightAll = this.cell.h * this.rows;
      r.setScissorTest(true);
      this.camera.aspect = this.cell.w / this.cell.h;
      this.camera.updateProjectionMatrix();
      this.views.forEach((view, i) => {
        const x = (i % this.columns) * this.cell.w;
        const y = heightAll - (Math.floor(i / this.columns) + 1) * this.cell.h;
        r.setViewport(x, y, this.cell.w - 2, this.cell.h - 2);
        r.setScissor(x, y, this.cell.w - 2, this.cell.h - 2);
        r.render(view.scene, this.camera);
      });
      this.placeLabels();
    }

    // The schematic's labels over the first view, where their points project.
    placeLabels() {
      const layer = this.root.querySelector(".cb-labels");
      if (!this.cell) return;
      const show = this.root.querySelector(".cb-show-labels").checked;
      layer.style.display = show ? "" : "none";
      if (!show || !this.views) return;
      const groups = this.views[0].groups;
      const v = new THREE.Vector3();
      layer.querySelectorAll(".cb-label").forEach((element, i) => {
        const label = this.p.scene.labels[i];
        v.set(...label.point).applyQuaternion(groups[label.body].quaternion)
          .add(groups[label.body].position).project(this.camera);
        const visible = v.z < 1 && Math.abs(v.x) <= 1 && Math.abs(v.y) <= 1;
        element.style.display = visible ? "" : "none";
        element.style.left = `${(v.x + 1) / 2 * this.cell.w}px`;
        element.style.top = `${(1 - v.y) / 2 * this.cell.h}px`;
      });
    }

    toggle() {
      this.playing = !this.playing;
      this.root.querySelector(".cb-play").textContent = this.playing ? "pause" : "play";
      if (this.playing && this.frame >= this.times.length - 1) this.show(0);
      const tick = () => {
        if (!this.playing) return;
        if (this.frame >= this.times.length - 1) { this.toggle(); return; }
        this.show(this.frame + 1);
        window.setTimeout(() => window.requestAnimationFrame(tick), 40);
      };
      if (this.playing) window.requestAnimationFrame(tick);
    }
  }

  window.clearbenchViewers = [];
  for (const root of document.querySelectorAll(".cb-viewer")) {
    const payload = JSON.parse(root.querySelector("script.cb-viewer-data").textContent);
    const viewer = new Viewer(root, payload);
    window.clearbenchViewers.push(viewer);
    viewer.start().catch((error) => {
      root.querySelector(".cb-stage").textContent = `The viewer could not start: ${error}`;
      root.dataset.ready = "failed";
    });
  }
})();
