// Loads the glb named by ?glb= with three.js's GLTFLoader and draws it from its own camera,
// lit by the baked lightmap alone: for each material whose extras carry RAD_lightmap, the
// named texture becomes material.lightMap on the uv set texCoord (three.js's Texture.channel:
// TEXCOORD_1 is the attribute uv1), decoded from sRGB and scaled by 'scale' (lightMapIntensity),
// so three.js adds it to the irradiance and shades albedo x irradiance / pi + emission (a
// Lambert material), as
// `rad render --method lightmap` does. No tone mapping: the output is sRGB of the clamped
// radiance, as the tool's PNGs are (exposure 1). The title says "ready" once drawn, or
// "error: ..." when something failed; with ?report=1 the drawn pixels (RGBA, bottom row first)
// go to the server as POST /pixels before it says "ready".
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const query = new URLSearchParams(location.search);
const url = query.get('glb') || 'baked.glb';
const width = Number(query.get('w')) || window.innerWidth;
const height = Number(query.get('h')) || window.innerHeight;

async function main() {
    const renderer = new THREE.WebGLRenderer({ antialias: query.get('aa') !== '0', preserveDrawingBuffer: true });
    renderer.setPixelRatio(1);
    renderer.setSize(width, height);
    renderer.outputColorSpace = THREE.SRGBColorSpace;
    renderer.toneMapping = THREE.NoToneMapping;
    document.body.appendChild(renderer.domElement);

    const gltf = await new GLTFLoader().loadAsync(url);
    // The lightmap is the irradiance of a Lambertian solution: each glTF material becomes a
    // MeshLambertMaterial of the same colours (three.js's standard material would take the
    // energy of its 4% specular layer out of the diffuse light, a few percent darker).
    const lambert = new Map();
    gltf.scene.traverse((o) => {
        if (!o.isMesh || Array.isArray(o.material)) return;
        const src = o.material;
        if (!lambert.has(src))
            lambert.set(src, new THREE.MeshLambertMaterial({ name: src.name, color: src.color, emissive: src.emissive,
                                                             emissiveIntensity: src.emissiveIntensity, side: src.side,
                                                             userData: src.userData }));
        o.material = lambert.get(src);
    });
    let lightmapped = 0;
    for (const m of lambert.values()) {
        const info = m.userData.RAD_lightmap; // the material's extras (GLTFLoader puts them in userData)
        if (!info) continue;
        const texture = await gltf.parser.getDependency('texture', info.texture);
        texture.channel = info.texCoord;
        texture.colorSpace = info.encoding === 'srgb' ? THREE.SRGBColorSpace : THREE.LinearSRGBColorSpace;
        m.lightMap = texture;
        m.lightMapIntensity = info.scale;
        m.needsUpdate = true;
        ++lightmapped;
    }
    if (lightmapped === 0) throw new Error('no material names a RAD_lightmap');
    if (gltf.cameras.length === 0) throw new Error('the file has no camera');
    const camera = gltf.cameras[0];
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
    // The view is read from the drawing buffer right after a frame is drawn, not from the
    // browser's screenshot: under load the compositor can hand the screenshot a canvas it has not
    // shown yet (all black). A black read is drawn again, up to 60 frames.
    const gl = renderer.getContext();
    let frames = 0, busy = false;
    renderer.setAnimationLoop(() => {
        if (busy) return;
        renderer.render(gltf.scene, camera);
        if (++frames < 3) return;
        const px = new Uint8Array(width * height * 4);
        gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, px);
        if (!px.some((v, i) => (i & 3) !== 3 && v !== 0) && frames < 60) return;
        busy = true;
        renderer.setAnimationLoop(null);
        if (frames >= 60) { say('error: the canvas stayed black for 60 frames'); return; }
        if (!query.get('report')) { say('ready'); return; }
        fetch(`/pixels?w=${width}&h=${height}`, { method: 'POST', body: px })
            .then((r) => say(r.ok ? 'ready' : 'error: the server refused the pixels'))
            .catch((e) => say('error: sending the pixels: ' + e.message));
    });
}

// the title, and with ?report=1 the server that serves the page (tests/web/check.mjs)
function say(s) {
    document.title = s;
    if (query.get('report')) fetch('/status?s=' + encodeURIComponent(s)).catch(() => {});
}

main().catch((e) => { say('error: ' + e.message); console.error(e); });
