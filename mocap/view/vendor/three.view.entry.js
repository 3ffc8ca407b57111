export {
  WebGLRenderer, Scene, PerspectiveCamera, Color, BufferGeometry, BufferAttribute,
  LineSegments, LineLoop, LineBasicMaterial, GridHelper, Mesh, InstancedMesh, SphereGeometry,
  MeshLambertMaterial, MeshBasicMaterial, AmbientLight, DirectionalLight, Vector2, Vector3,
  Matrix4, Raycaster, ArrowHelper, Group, Object3D, DynamicDrawUsage, AxesHelper
} from 'three';
export { OrbitControls } from 'three/addons/controls/OrbitControls.js';
