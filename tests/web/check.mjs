// node tests/web/check.mjs --glb FILE.glb --out SHOT.png --size WxH [--aa 0] [--tol T] [--mean-tol M] --ref VIEW.png
//                          [[--tol T2] [--mean-tol M2] --ref VIEW2.png ...]
//
// Shows FILE.glb in headless Chromium through tests/web/index.html (three.js from
// build/web/node_modules), writes the canvas it drew into SHOT.png, and compares it with each
// reference view the rad tool drew of the same camera: both decoded from sRGB to linear, the
// luminance (Rec. 709 weights) averaged over a 4x4 grid of regions, and every region's mean
// must be within --tol (relative; a region darker than 0.01 is compared against 0.01) of the
// reference's, and their mean within --mean-tol (each --ref takes the tolerances given before
// it; defaults 0.05 and 0.02). --aa 0: the page draws without MSAA (WebGL resolves it in sRGB,
// which darkens edges; the tool averages linear radiance). Serves the repository (the folder it is run from) on 127.0.0.1 with an
// ephemeral port, the glb at /scene.glb; the page reports "ready" or its error to /status.
// Exit 0: every comparison within the tolerance; 1: a difference or the page failed; 2: usage.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';
import { spawn } from 'node:child_process';

const args = { ref: [], tol: '0.05', 'mean-tol': '0.02' };
for (let i = 2; i < process.argv.length; i += 2) {
    const k = process.argv[i].replace(/^--/, ''), v = process.argv[i + 1];
    if (v === undefined) { console.error(`check.mjs: ${process.argv[i]} needs a value`); process.exit(2); }
    if (k === 'ref') args.ref.push({ file: v, tol: Number(args.tol), meanTol: Number(args['mean-tol']) }); else args[k] = v;
}
if (!args.glb || !args.out || !args.size || args.ref.length === 0) {
    console.error('usage: node tests/web/check.mjs --glb FILE.glb --out SHOT.png --size WxH --ref VIEW.png [--tol 0.05]');
    process.exit(2);
}
const [W, H] = args.size.split('x').map(Number);
const chromium = args.chromium || process.env.CHROMIUM || 'chromium';

// ---- PNG decoding (8-bit grey, RGB or RGBA, not interlaced): what both sides write
function paeth(a, b, c) {
    const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
    return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}
function readPng(file) {
    const d = fs.readFileSync(file);
    if (d.readUInt32BE(0) !== 0x89504e47) throw new Error(`${file} is not a PNG`);
    let off = 8, w = 0, h = 0, depth = 0, type = 0, interlace = 0;
    const idat = [];
    while (off < d.length) {
        const len = d.readUInt32BE(off), kind = d.toString('latin1', off + 4, off + 8), body = d.subarray(off + 8, off + 8 + len);
        if (kind === 'IHDR') { w = body.readUInt32BE(0); h = body.readUInt32BE(4); depth = body[8]; type = body[9]; interlace = body[12]; }
        else if (kind === 'IDAT') idat.push(body);
        else if (kind === 'IEND') break;
        off += 12 + len;
    }
    const ch = { 0: 1, 2: 3, 6: 4 }[type];
    if (depth !== 8 || !ch || interlace) throw new Error(`${file}: only 8-bit grey, RGB or RGBA PNGs without interlace are read`);
    const raw = zlib.inflateSync(Buffer.concat(idat)), stride = w * ch, px = Buffer.alloc(h * stride);
    for (let y = 0; y < h; ++y) {
        const f = raw[y * (stride + 1)], src = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
        for (let x = 0; x < stride; ++x) {
            const a = x >= ch ? px[y * stride + x - ch] : 0, b = y ? px[(y - 1) * stride + x] : 0;
            const c = x >= ch && y ? px[(y - 1) * stride + x - ch] : 0;
            const p = f === 0 ? 0 : f === 1 ? a : f === 2 ? b : f === 3 ? (a + b) >> 1 : paeth(a, b, c);
            px[y * stride + x] = (src[x] + p) & 255;
        }
    }
    return { w, h, ch, px };
}
// an RGBA PNG of WebGL's pixels (rows bottom first), so the file shows what was compared
function writePng(file, w, h, rgba) {
    const raw = Buffer.alloc(h * (w * 4 + 1));
    for (let y = 0; y < h; ++y) rgba.copy(raw, y * (w * 4 + 1) + 1, (h - 1 - y) * w * 4, (h - y) * w * 4);
    const crcTable = Array.from({ length: 256 }, (_, n) => {
        let c = n;
        for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
        return c >>> 0;
    });
    const chunk = (kind, body) => {
        const head = Buffer.alloc(8), tail = Buffer.alloc(4), typed = Buffer.concat([Buffer.from(kind, 'latin1'), body]);
        let c = 0xffffffff;
        for (const b of typed) c = crcTable[(c ^ b) & 255] ^ (c >>> 8);
        head.writeUInt32BE(body.length, 0);
        head.write(kind, 4, 'latin1');
        tail.writeUInt32BE((c ^ 0xffffffff) >>> 0, 0);
        return Buffer.concat([head, body, tail]);
    };
    const ihdr = Buffer.alloc(13);
    ihdr.writeUInt32BE(w, 0);
    ihdr.writeUInt32BE(h, 4);
    ihdr[8] = 8; ihdr[9] = 6; // 8-bit RGBA, filter and interlace bytes 0
    fs.writeFileSync(file, Buffer.concat([Buffer.from([0x89, 0x50, 0x4e, 0x47, 13, 10, 26, 10]), chunk('IHDR', ihdr),
                                          chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]));
}
const lin = (c) => { c /= 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); };
function regions(img, n = 4) {
    const sum = new Array(n * n).fill(0), cnt = new Array(n * n).fill(0);
    for (let y = 0; y < img.h; ++y)
        for (let x = 0; x < img.w; ++x) {
            const o = (y * img.w + x) * img.ch;
            const r = lin(img.px[o]), g = img.ch >= 3 ? lin(img.px[o + 1]) : r, b = img.ch >= 3 ? lin(img.px[o + 2]) : r;
            const k = Math.floor((y * n) / img.h) * n + Math.floor((x * n) / img.w);
            sum[k] += 0.2126 * r + 0.7152 * g + 0.0722 * b;
            ++cnt[k];
        }
    return sum.map((s, k) => s / cnt[k]);
}

// ---- the page, served
const root = process.cwd();
const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
                '.glb': 'model/gltf-binary', '.png': 'image/png' };
let status = null, canvas = null;
const server = http.createServer((req, res) => {
    const u = new URL(req.url, 'http://127.0.0.1');
    if (u.pathname === '/status') { status = u.searchParams.get('s'); res.end('ok'); return; }
    if (u.pathname === '/pixels' && req.method === 'POST') {
        const parts = [];
        req.on('data', (d) => parts.push(d));
        req.on('end', () => {
            const px = Buffer.concat(parts);
            const good = Number(u.searchParams.get('w')) === W && Number(u.searchParams.get('h')) === H && px.length === W * H * 4;
            if (good) canvas = px;
            res.writeHead(good ? 200 : 400);
            res.end();
        });
        return;
    }
    const file = u.pathname === '/scene.glb' ? path.resolve(args.glb) : path.join(root, path.normalize(decodeURIComponent(u.pathname)));
    if (u.pathname !== '/scene.glb' && !file.startsWith(root + path.sep)) { res.writeHead(403); res.end(); return; }
    fs.readFile(file, (err, data) => {
        if (err) { res.writeHead(404); res.end(); return; }
        res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' });
        res.end(data);
    });
});
await new Promise((ok) => server.listen(0, '127.0.0.1', ok));
const url = `http://127.0.0.1:${server.address().port}/tests/web/index.html?glb=/scene.glb&w=${W}&h=${H}&report=1${args.aa ? `&aa=${args.aa}` : ""}`;
fs.rmSync(args.out, { force: true });
// SwiftShader: WebGL on the CPU, so no GPU is needed; the virtual time budget lets the
// browser wait for the page's fetches and first frames. Chromium's own screenshot only keeps the
// browser up that long (a side file, removed): the compared view is the canvas the page posts.
const side = path.resolve(args.out) + '.browser.png';
const flags = ['--headless', '--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
               '--hide-scrollbars', `--window-size=${W},${H}`, '--virtual-time-budget=30000', `--screenshot=${side}`, url];
const rc = await new Promise((ok) => {
    const p = spawn(chromium, flags, { stdio: ['ignore', 'ignore', 'pipe'] });
    let err = '';
    p.stderr.on('data', (d) => { err += d; });
    const timer = setTimeout(() => p.kill('SIGKILL'), 120000);
    p.on('error', (e) => { clearTimeout(timer); console.error(`check.mjs: cannot run ${chromium}: ${e.message}`); ok(-1); });
    p.on('close', (code) => { clearTimeout(timer); if (code) console.error(err.split('\n').slice(-8).join('\n')); ok(code); });
});
server.close();
console.log(`page: ${status === null ? 'said nothing (did the modules load? is build/web/node_modules/three there?)' : status}`);
fs.rmSync(side, { force: true });
if (rc !== 0) { console.log(`FAIL chromium exited ${rc}`); process.exit(1); }
if (status !== 'ready' || canvas === null) { console.log('FAIL the page did not draw the scene'); process.exit(1); }
writePng(args.out, W, H, canvas);

const shot = regions(readPng(args.out));
let bad = 0;
for (const { file: ref, tol, meanTol } of args.ref) {
    const img = readPng(ref);
    if (img.w !== W || img.h !== H) { console.log(`FAIL ${ref} is ${img.w}x${img.h}, the view ${W}x${H}`); bad = 1; continue; }
    const r = regions(img);
    const rel = r.map((m, k) => Math.abs(shot[k] - m) / Math.max(m, 0.01));
    const worst = Math.max(...rel), k = rel.indexOf(worst), mean = rel.reduce((a, b) => a + b) / rel.length;
    const good = worst <= tol && mean <= meanTol;
    console.log(`${good ? 'ok  ' : 'FAIL'} ${path.basename(ref)}: 4x4 mean luminance, largest relative difference ` +
                `${(100 * worst).toFixed(2)}% (region ${k % 4},${Math.floor(k / 4)}: three.js ${shot[k].toFixed(4)}, ` +
                `rad ${r[k].toFixed(4)}), mean ${(100 * mean).toFixed(2)}%; tolerances ${(100 * tol).toFixed(0)}% and ` +
                `${(100 * meanTol).toFixed(0)}%`);
    if (!good) bad = 1;
}
process.exit(bad);
