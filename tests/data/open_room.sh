#!/usr/bin/env bash
# open_room.sh - writes OUT.obj and OUT.mtl: a closed room 4 x 3 x 4 (walls facing in, albedo
# 0.7) with a 1.6 x 1.6 opening in the middle of its ceiling, a 0.8 block on the floor, and a
# one-sided emissive panel 3 x 3 (radiance 5) 0.4 above the opening, facing down: an emitter
# larger than the opening it lights the room through, so most of it is hidden from any point
# inside. Each quad but the panel is cut into N x N cells (two triangles each): N 1 gives 30
# triangles, N 20 11 202.
#   bash tests/data/open_room.sh OUT N
set -eu
OUT=$1
N=${2:-1}
cat > "$OUT.mtl" <<'MTL'
newmtl wall
Kd 0.7 0.7 0.7
newmtl lamp
Kd 0 0 0
Ke 5 5 5
MTL
awk -v N="$N" -v mtl="$(basename "$OUT").mtl" '
function quad(px, py, pz, ux, uy, uz, vx, vy, vz, n,   i, j, a) {
    # the cells of p + s u + t v, wound so that the normal is u x v
    for (j = 0; j <= n; ++j)
        for (i = 0; i <= n; ++i)
            printf "v %.6f %.6f %.6f\n", px + ux * i / n + vx * j / n, py + uy * i / n + vy * j / n, pz + uz * i / n + vz * j / n
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            a = base + j * (n + 1) + i + 1
            printf "f %d %d %d\nf %d %d %d\n", a, a + 1, a + n + 2, a, a + n + 2, a + n + 1
        }
    base += (n + 1) * (n + 1)
}
BEGIN {
    base = 0
    print "mtllib " mtl
    print "o room"
    print "usemtl wall"
    quad(0, 0, 0, 0, 0, 4, 4, 0, 0, N)            # floor, facing +y
    quad(0, 0, 0, 0, 3, 0, 0, 0, 4, N)            # x = 0, facing +x
    quad(4, 0, 0, 0, 0, 4, 0, 3, 0, N)            # x = 4, facing -x
    quad(0, 0, 0, 4, 0, 0, 0, 3, 0, N)            # z = 0, facing +z
    quad(0, 0, 4, 0, 3, 0, 4, 0, 0, N)            # z = 4, facing -z
    quad(0, 3, 0, 4, 0, 0, 0, 0, 1.2, N)          # the ceiling around the opening, facing -y
    quad(0, 3, 2.8, 4, 0, 0, 0, 0, 1.2, N)
    quad(0, 3, 1.2, 1.2, 0, 0, 0, 0, 1.6, N)
    quad(2.8, 3, 1.2, 1.2, 0, 0, 0, 0, 1.6, N)
    quad(2.6, 0.8, 0.6, 0, 0, 0.8, 0.8, 0, 0, N)  # the block: top, then four sides facing out
    quad(2.6, 0, 0.6, 0, 0, 0.8, 0, 0.8, 0, N)
    quad(3.4, 0, 0.6, 0, 0.8, 0, 0, 0, 0.8, N)
    quad(2.6, 0, 0.6, 0, 0.8, 0, 0.8, 0, 0, N)
    quad(2.6, 0, 1.4, 0.8, 0, 0, 0, 0.8, 0, N)
    print "usemtl lamp"
    quad(0.5, 3.4, 0.5, 3, 0, 0, 0, 0, 3, 1)      # the panel above the opening, facing -y
}' > "$OUT.obj"
