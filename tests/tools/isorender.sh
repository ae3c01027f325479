# SPDX-License-Identifier: BSD-3-Clause
# isorender end to end: image, mesh, stats and progress files; bad input.
. "$(dirname "$0")/lib.sh"

"$bin/isogen" sphere --dims 48x40x36 --type uint8 -o "$work/" --quiet
"$bin/isobrick" sphere_48x40x36_uint8.raw -o s.ibv --brick-size 8 --quiet

run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y -o p.png --lod off \
    --mesh p.ply --stats p.json --progress p.csv --software
check "progressive render succeeds" test "$rc" = 0
check "the image is a PNG" sh -c 'head -c 8 p.png | od -An -tx1 | grep -q "89 50 4e 47 0d 0a 1a 0a"'
check "the summary is printed" grep -q "triangles" "$work/.out"
check "the cache table is printed" grep -q "cache statistics" "$work/.out"
check "the cache table shows reading ahead" grep -q "read ahead" "$work/.out"
check "the PLY header" sh -c 'head -c 200 p.ply | grep -q "format binary_little_endian 1.0"'
# the mesh as binary STL by the name's extension: 84 bytes, then 50 per triangle of the run
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y -o p2.png --lod off \
    --mesh p.stl --stats p2.json --software --quiet
check "--mesh .stl succeeds" test "$rc" = 0
triangles=$(json_number triangles p2.json)
check "the STL holds the run's $triangles triangles" test "$(stat -c %s p.stl)" = $((84 + 50 * triangles))
expect_error 2 "p.off" "$bin/isorender" s.ibv --iso 100.5 --mesh p.off -o x.png
check "an unknown mesh format writes nothing" sh -c '! test -e p.off && ! test -e x.png'
json=$(cat p.json)
for key in cache budget_bytes resident_bytes resident_peak_bytes hits misses evictions \
           bytes_decompressed decode_seconds bricks_touched bricks_total hit_rate \
           peak_rss_bytes rays seeds cells triangles intersection_s propagation_s \
           extraction_s rendering_s visible_triangles overdraw occlusion deferred_cells \
           retired_rays ray_nodes prefetch prefetch_mode cull culled_triangles prefetched prefetch_hits \
           bytes_read_disk wait_seconds; do
    check "stats has \"$key\"" sh -c 'printf "%s" "$0" | grep -q "\"$1\":"' "$json" "$key"
done
check "every pixel had its ray" sh -c 'printf "%s" "$0" | grep -q "\"rays\": 19200, \"rays_total\": 19200, \"done\": true"' "$json"
# the first six columns are those scripts read since the start; later ones are appended
check "progress header" test "$(head -1 p.csv)" = \
    "time_s,rays,seeds,cells,triangles,final_pixel_pct,visible_triangles,overdraw"
check "progress ends with every ray and 100 % final pixels" sh -c 'tail -1 p.csv | grep -q "^[0-9.]*,19200,[0-9]*,[0-9]*,[0-9]*,100.0000,"'
check "a checkpoint each time the ray count doubles" test "$(grep -c . p.csv)" = 17
# final_pixel_pct never decreases
check "final pixels only grow" awk -F, 'NR > 2 && $6 + 0 < prev { exit 1 } { prev = $6 + 0 }' p.csv
triangles=$(json_number triangles p.json)
faces=$(head -c 400 p.ply | sed -n 's/^element face \([0-9]*\).*/\1/p')
check "the PLY holds every triangle ($faces = $triangles)" test "$faces" = "$triangles"
# overdraw: the visible triangles (owning a final pixel) are among the extracted ones
visible=$(json_number visible_triangles p.json)
check "0 < visible ($visible) <= triangles ($triangles)" test "$visible" -gt 0 -a "$visible" -le "$triangles"
check "the last checkpoint's visible triangles are the stats'" sh -c \
    'tail -1 p.csv | cut -d, -f7 | grep -qx "$0"' "$visible"
check "visible triangles only grow" awk -F, 'NR > 2 && $7 + 0 < prev { exit 1 } { prev = $7 + 0 }' p.csv

# occlusion off extracts at least as much and makes the same picture
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y -o o.png --lod off \
    --occlusion off --stats o.json --software --quiet
check "occlusion off succeeds" test "$rc" = 0
check "occlusion off says so" grep -q '"occlusion": false, "deferred_cells": 0, "retired_rays": 0,' o.json
retired=$(json_number retired_rays p.json)
check "occlusion on retires rays in bulk (0 < $retired < 19200)" test "$retired" -gt 0 -a "$retired" -lt 19200
walked=$(json_number ray_nodes p.json)
walked_off=$(json_number ray_nodes o.json)
check "the rays walk fewer nodes with occlusion ($walked < $walked_off)" test "$walked" -lt "$walked_off"
off=$(json_number triangles o.json)
check "occlusion on extracts no more ($triangles <= $off)" test "$triangles" -le "$off"
check "occlusion on and off make the same picture" cmp -s p.png o.png
expect_error 2 "--occlusion" "$bin/isorender" s.ibv --iso 1 --occlusion maybe -o x.png

# reading ahead off: the same picture, nothing loaded ahead
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y -o n.png \
    --prefetch off --stats n.json --software --quiet
check "prefetch off succeeds" test "$rc" = 0
check "prefetch off says so" grep -q '"prefetch": false, "prefetch_mode": "off"' n.json
check "prefetch on by default, and says which" grep -q '"prefetch": true, "prefetch_mode": "on"' p.json
check "prefetch off loads nothing ahead" grep -q '"prefetched": 0, "prefetch_hits": 0' n.json
check "prefetch on and off make the same picture" cmp -s p.png n.png
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y -o a.png \
    --prefetch always --stats a.json --software --quiet
check "prefetch always succeeds" test "$rc" = 0
check "prefetch always says it is on, and always" grep -q '"prefetch": true, "prefetch_mode": "always"' a.json
check "prefetch always and off make the same picture" cmp -s a.png n.png
expect_error 2 "--prefetch must be on, off or always" "$bin/isorender" s.ibv --iso 1 \
    --prefetch maybe -o x.png

# culling: on by default, off when the mesh is written (unless asked for); the same picture
# either way, and on one thread the culled and kept triangles add up to those kept without
cull_run() { # NAME OPTIONS...
    cull_name=$1
    shift
    run_capture "$bin/isorender" s.ibv --iso 100.5 --size 64x48 --view -y --lod off --threads 1 \
        -o "$cull_name.png" --stats "$cull_name.json" --software --quiet "$@"
}
cull_run c
check "culling by default succeeds" test "$rc" = 0
check "culling is on by default" grep -q '"cull": true' c.json
cull_run c0 --cull off
check "--cull off says so" grep -q '"cull": false, "culled_triangles": 0' c0.json
kept=$(json_number triangles c.json) culled=$(json_number culled_triangles c.json)
whole=$(json_number triangles c0.json)
check "some triangles are culled (0 < $culled)" test "$culled" -gt 0
check "kept and culled add up to the triangles kept without ($kept + $culled = $whole)" \
    test $((kept + culled)) = "$whole"
check "culling on and off make the same picture" cmp -s c.png c0.png
cull_run cm --mesh cm.ply
check "with --mesh nothing is culled" grep -q '"cull": false, "culled_triangles": 0' cm.json
cull_run cmc --mesh cmc.ply --cull on
check "--mesh with --cull on culls" grep -q '"cull": true' cmc.json
faces=$(head -c 400 cmc.ply | sed -n 's/^element face \([0-9]*\).*/\1/p')
check "the PLY holds the kept triangles ($faces = $kept)" test "$faces" = "$kept"
check "culled images match with and without --mesh" cmp -s c.png cm.png
expect_error 2 "--cull" "$bin/isorender" s.ibv --iso 1 --cull maybe -o x.png

# the full extraction and the progressive one make the same picture
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y -o f.png --full --software --quiet
check "full render succeeds" test "$rc" = 0
check "full and progressive images are identical" cmp -s p.png f.png

# adaptive resolution: at a 4-pixel error the far side comes from coarser levels, and once
# every ray has been cast the progressive image is the full extraction's at the view's levels
for t in 1 2; do
    run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y --azimuth 30 \
        --pixel-error 4 --threads $t -o l$t.png --stats l$t.json --software --quiet
    check "lod render on $t threads succeeds" test "$rc" = 0
done
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --view -y --azimuth 30 \
    --pixel-error 4 -o fl.png --stats fl.json --full-lod --software --quiet
check "--full-lod succeeds" test "$rc" = 0
check "--full-lod says so" grep -q '"mode": "full-lod"' fl.json
check "lod uses a coarse level" sh -c '! grep -q "\"level\": 1, \"bricks_touched\": 0," fl.json'
check "lod and --full-lod images are identical (1 thread)" cmp -s l1.png fl.png
check "lod and --full-lod images are identical (2 threads)" cmp -s l2.png fl.png
expect_error 2 "--full-lod" "$bin/isorender" s.ibv --iso 100.5 --full --full-lod -o x.png
expect_error 2 "--full-lod" "$bin/isorender" s.ibv --iso 100.5 --full-lod --lod off -o x.png

# limits: a ray budget
run_capture "$bin/isorender" s.ibv --iso 100.5 --size 160x120 --rays 100 -o r.png --stats r.json --software --quiet --warm
check "a ray budget stops early" grep -q '"rays": 100, "rays_total": 19200, "done": false' r.json
check "a warm run says so" grep -q '"warm": true' r.json

# bad input: one line, non-zero, nothing written
expect_error 2 "--iso" "$bin/isorender" s.ibv -o x.png
check "no image without --iso" test ! -e x.png
expect_error 1 "nothere.ibv" "$bin/isorender" nothere.ibv --iso 1 -o x.png
expect_error 2 "--size" "$bin/isorender" s.ibv --iso 1 --size 12 -o x.png
expect_error 2 "view" "$bin/isorender" s.ibv --iso 1 --view +w -o x.png
expect_error 2 "camera" "$bin/isorender" s.ibv --iso 1 --camera 0,0,0,0,0,0,0,0,1,30 -o x.png
expect_error 1 "exists" "$bin/isorender" s.ibv --iso 100.5 --size 16x12 -o p.png --software
head -c 1000 s.ibv >cut.ibv
expect_error 1 "cut.ibv" "$bin/isorender" cut.ibv --iso 1 -o x.png
check "no image after errors" test ! -e x.png
finish
