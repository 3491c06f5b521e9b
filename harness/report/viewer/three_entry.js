// The parts of three.js the report's viewer uses, bundled into vendor/three-viewer.min.js as
// one global `THREE` (see vendor/README.md for the command). Only what is listed here is kept.
export {
  AmbientLight, BoxGeometry, BufferAttribute, BufferGeometry, CapsuleGeometry, CircleGeometry,
  Color, CylinderGeometry, DirectionalLight, DoubleSide, Float32BufferAttribute, Group,
  InstancedMesh, LineBasicMaterial, LineSegments, Matrix4, Mesh, MeshBasicMaterial,
  MeshLambertMaterial, OrthographicCamera, PerspectiveCamera, PlaneGeometry, Quaternion,
  RingGeometry, Scene, SphereGeometry, TorusGeometry, Vector3, WebGLRenderer,
} from "three";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
