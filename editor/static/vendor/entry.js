// What bgr serve's page imports: three.js, its glTF loader and its orbit controls.
export * from "three";
export { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
