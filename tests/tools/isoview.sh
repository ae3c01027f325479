# SPDX-License-Identifier: BSD-3-Clause
# isoview end to end, in a virtual X server (xvfb-run; Mesa's llvmpipe through GLX): once
# refinement completes, the window shows what isorender renders for the same view; a scripted
# walk (orbit, zoom, isovalue changes, full extraction) refines, keeps the cache within its
# budget and exits on its own with status 0; bad input fails with one line before any window.
. "$(dirname "$0")/lib.sh"

compare=$bin/tests/png_compare
"$bin/isogen" sphere --dims 128x128x128 --type uint16 -o "$work/" --quiet
"$bin/isobrick" sphere_128x128x128_uint16.raw -o s.ibv --brick-size 16 --quiet

# bad input: one line, non-zero, before any window opens (no display needed)
expect_error 2 "--iso" "$bin/isoview" s.ibv
expect_error 2 "--size" "$bin/isoview" s.ibv --iso 1 --size 12
expect_error 2 "--lod" "$bin/isoview" s.ibv --iso 1 --lod maybe
expect_error 2 "--aa '0' is not a sample count (1 to 16)" "$bin/isoview" s.ibv --iso 1 --aa 0
expect_error 2 "--aa '32' is not a sample count (1 to 16)" "$bin/isoview" s.ibv --iso 1 --aa 32
expect_error 2 "--iso given 2 times: isoview shows one surface" "$bin/isoview" s.ibv --iso 1 --iso 2
expect_error 1 "nothere.ibv" "$bin/isoview" nothere.ibv --iso 1
expect_error 2 "view" "$bin/isoview" s.ibv --iso 1 --view +w
printf 'iso 1\norbit 10\n' >bad.txt
expect_error 1 "bad.txt:2" "$bin/isoview" s.ibv --iso 1 --script bad.txt
# a script's views and cameras are checked as --view and --camera are, before any window
printf 'view +w\n' >badview.txt
expect_error 1 "badview.txt:1: view '+w' is not one of" "$bin/isoview" s.ibv --iso 1 \
    --script badview.txt
printf 'iso 1\ncamera 1,2,3\n' >badcamera.txt
expect_error 1 "badcamera.txt:2: --camera '1,2,3' is not" "$bin/isoview" s.ibv --iso 1 \
    --script badcamera.txt
printf 'camera 0,0,0,0,0,0,0,0,1,35\n' >samepoint.txt
expect_error 1 "samepoint.txt:1: camera: eye and target coincide" "$bin/isoview" s.ibv --iso 1 \
    --script samepoint.txt
expect_error 1 "cannot open a window" env -u DISPLAY -u WAYLAND_DISPLAY "$bin/isoview" s.ibv --iso 1
# --clip as isorender takes it, and the script's clip on|off
expect_error 2 "bad --clip 'w=3'" "$bin/isoview" s.ibv --iso 1 --clip w=3
expect_error 2 "bad --clip '0,0,0,1'" "$bin/isoview" s.ibv --iso 1 --clip 0,0,0,1
expect_error 2 "at most 6 --clip and --clip-index planes" "$bin/isoview" s.ibv --iso 1 --clip x=1 --clip x=2 \
    --clip x=3 --clip x=4 --clip x=5 --clip x=6 --clip x=7
printf 'clip maybe\n' >badclip.txt
expect_error 1 "badclip.txt:1: bad arguments to 'clip'" "$bin/isoview" s.ibv --iso 1 --clip x=1 \
    --script badclip.txt

if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "isoview: window tests skipped: xvfb-run is missing (Debian package xvfb)"
    [ "$failed" = 0 ] && exit 77
    finish
fi

# (under AddressSanitizer, $preload from lib.sh keeps Mesa's driver loaded to the end)

# view ARGS...: runs isoview in its own virtual screen; sets $rc, $out, $err and $elapsed (s).
view() {
    started=$(date +%s%N)
    in_xvfb 99 1280x1024x24 "$bin/isoview" "$@"
    elapsed=$(( ($(date +%s%N) - started) / 1000000000 ))
}

# pct_differ A B: the percentage of pixels of A and B that differ by more than 2 levels
pct_differ() {
    "$compare" "$1" "$2" --level 2 --max-pct 100 | sed -n 's/.* pixels (\([0-9.]*\) %).*/\1/p'
}

# same_image DESCRIPTION A B: at most 0.2 % of the pixels differ by more than 2 levels (the
# window is drawn by the same renderer as isorender's image; rasterisers may differ on a few
# silhouette pixels and by a level of rounding)
same_image() {
    line=$("$compare" "$2" "$3" --level 2 --max-pct 0.2)
    status=$?
    echo "$line"
    if [ "$status" = 0 ]; then ok; else bad "$1: $line"; fi
}

camera=200,-160,190,63.5,63.5,63.5,0,0,1,35
cat >walk.txt <<EOF
# the start (--view -y, iso 1000.5) once every ray has been cast, with and without the overlay
wait done
screenshot hud.png
overlay off
screenshot start.png
# interaction: every change restarts the progressive order
orbit 40 -15
wait 0.2
zoom 1.5
iso 2000.5
wait 0.2
orbit -25 20
camera $camera
wait done
screenshot camera.png
full
wait done
screenshot full.png
view -y
iso 1000.5
wait done
screenshot view.png
quit
EOF
view s.ibv --iso 1000.5 --size 320x240 --lod off --cache-mb 1 --script walk.txt \
    --stats walk.json --exit-after 90
check "the scripted walk exits with 0 (got $rc: $err)" test "$rc" = 0
check "it quits at the script's end, before --exit-after (took ${elapsed} s)" test "$elapsed" -lt 90
check "the cache table is printed" grep -q "cache statistics" "$work/.out"
for shot in hud start camera full view; do
    check "screenshot $shot.png is written" test -s "$shot.png"
done

"$bin/isorender" s.ibv --iso 1000.5 --size 320x240 --view -y --lod off -o r-start.png --quiet
"$bin/isorender" s.ibv --iso 2000.5 --size 320x240 --camera "$camera" --lod off -o r-camera.png \
    --quiet
same_image "the window shows isorender's image at the start" start.png r-start.png
same_image "... after orbit, zoom and isovalue changes, at a given camera" camera.png r-camera.png
same_image "... with the full extraction" full.png r-camera.png
same_image "... back at --view -y" view.png r-start.png
# the renderer: auto takes the software one where OpenGL is itself software (llvmpipe here)
if grep -q '"gl_renderer": "[^"]*llvmpipe' walk.json; then
    check "auto draws in software on llvmpipe" grep -q '"renderer": "software"' walk.json
fi
# each pass's course and the memory held (docs/isoview.md, "Statistics")
for key in views views_median first_frame_s final_85_s final_995_s complete_s view_frames \
           fps_moving memory engine_mesh_bytes visited_bytes coverage_bytes canvas_bytes \
           gpu_mesh_bytes rss_peak_bytes; do
    check "stats has \"$key\"" grep -q "\"$key\":" walk.json
done
check "five passes recorded" test "$(grep -o '"start_s"' walk.json | wc -l)" = 5
check "the last pass completed, its final pixels measured" \
    sh -c 'tr "{" "\n" <walk.json | grep "\"start_s\"" | tail -1 | grep -q "\"final_995_s\": [0-9]"'
# a drag (the script's, as the mouse's): coarse passes while the view moves, then the fine pass
# at the camera where it stopped, the image isorender draws there (its --azimuth turns the
# other way)
printf 'wait done\ndrag 30 0 0.6\nwait done\noverlay off\nscreenshot drag.png\nquit\n' >drag.txt
view s.ibv --iso 1000.5 --size 320x240 --script drag.txt --stats drag.json --exit-after 90
check "the drag exits with 0 (got $rc: $err)" test "$rc" = 0
"$bin/isorender" s.ibv --iso 1000.5 --size 320x240 --view -y --azimuth -30 -o r-drag.png --quiet
same_image "after a drag, the fine pass's image at the camera it stopped at" drag.png r-drag.png
check "passes ran while the view moved" grep -q '"moving": true' drag.json
check "and the last one did not" \
    sh -c 'tr "{" "\n" <drag.json | grep "\"start_s\"" | tail -1 | grep -q "\"moving\": false"'
check "frames were counted while it moved" sh -c '! grep -q "\"fps_moving\": 0.000" drag.json'
expect_error 2 "--drag-pixel-error '-1'" "$bin/isoview" s.ibv --iso 1 --drag-pixel-error -1
printf 'drag 30 0\n' >baddrag.txt
expect_error 1 "baddrag.txt:1: bad arguments to 'drag'" "$bin/isoview" s.ibv --iso 1 \
    --script baddrag.txt

# the same walk with the other renderer draws the same pictures
for r in opengl software; do
    grep -q "\"renderer\": \"$r\"" walk.json && continue
    sed "s/screenshot \([a-z]*\).png/screenshot $r-\1.png/" walk.txt >walk-$r.txt
    view s.ibv --iso 1000.5 --size 320x240 --lod off --cache-mb 1 --script walk-$r.txt \
        --stats walk-$r.json --exit-after 90 --renderer $r
    check "the walk with --renderer $r exits with 0 (got $rc: $err)" test "$rc" = 0
    check "its statistics say $r" grep -q "\"renderer\": \"$r\"" walk-$r.json
    same_image "$r: the start" $r-start.png r-start.png
    same_image "$r: at a given camera" $r-camera.png r-camera.png
    same_image "$r: the full extraction" $r-full.png r-camera.png
    same_image "$r: back at --view -y" $r-view.png r-start.png
done
expect_error 2 "--renderer 'gpu': must be auto, opengl or software" "$bin/isoview" s.ibv --iso 1 \
    --renderer gpu
expect_error 2 "--aa is OpenGL's" "$bin/isoview" s.ibv --iso 1 --renderer software --aa 4

hud=$(pct_differ hud.png start.png)
check "the overlay is drawn (${hud:-?} % of the pixels differ)" \
    awk -v p="${hud:-0}" 'BEGIN { exit !(p >= 1 && p <= 60) }'

# the compact overlay (the default) keeps to the bottom-left corner, clear of the model at the
# default zoom: the rectangle where the overlay changes the picture and the one where the
# picture without it differs from the bare background do not meet (so the corner, overlay off,
# is background)
"$bin/isorender" s.ibv --iso 99999 --size 320x240 --view -y -o bg.png --quiet 2>/dev/null
# bbox A B: "X Y W H" of the pixels of A and B that differ by more than 2 levels, or "none"
bbox() {
    "$compare" "$1" "$2" --level 2 --max-pct 100 --bbox | sed -n 's/^bbox //p'
}
hud_box=$(bbox hud.png start.png)
model_box=$(bbox start.png bg.png)
echo "overlay at $hud_box, model at $model_box"
# apart X Y W H X Y W H: the two rectangles do not intersect
apart() {
    [ "$#" = 8 ] && { [ $(($1 + $3)) -le "$5" ] || [ $(($5 + $7)) -le "$1" ] ||
        [ $(($2 + $4)) -le "$6" ] || [ $(($6 + $8)) -le "$2" ]; }
}
check "the compact overlay is in the lower half (at $hud_box)" \
    sh -c '[ "$#" = 4 ] && [ "$2" -ge 120 ] && [ "$1" -le 8 ]' sh $hud_box
check "the compact overlay does not cover the model ($hud_box, $model_box)" \
    apart $hud_box $model_box

json=$(cat walk.json 2>/dev/null)
for key in cache budget_bytes resident_peak_bytes hits misses evictions hit_rate bricks_touched \
           peak_rss_bytes file iso mode camera lod rays rays_total done triangles time \
           rendering_s extraction_wall_s passes fps frames mean; do
    check "stats has \"$key\"" sh -c 'printf "%s" "$0" | grep -q "\"$1\":"' "$json" "$key"
done
check "the last pass cast every ray" sh -c 'printf "%s" "$0" | grep -q "\"rays\": 76800, \"rays_total\": 76800, \"done\": true"' "$json"
check "and made triangles ($(json_number triangles walk.json))" test "$(json_number triangles walk.json)" -gt 0
check "five progressive passes ($(json_number passes walk.json))" test "$(json_number passes walk.json)" = 5
check "frames were drawn ($(json_number frames walk.json))" test "$(json_number frames walk.json)" -gt 5
peak=$(json_number resident_peak_bytes walk.json)
budget=$(json_number budget_bytes walk.json)
check "the cache stayed within its budget ($peak <= $budget)" test "$peak" -le "$budget"
check "the budget was binding (evictions: $(json_number evictions walk.json))" test "$(json_number evictions walk.json)" -gt 0
check "no load went over budget" test "$(json_number over_budget_pins walk.json)" = 0

# pausing: a change of view keeps the surface shown (no new pass) until refinement resumes;
# a change of isovalue resumes it, and the new isovalue's surface appears
cat >pause.txt <<EOF
overlay off
wait done
pause on
camera $camera
wait 0.5
screenshot paused-view.png
iso 2000.5
wait done
screenshot paused-iso.png
quit
EOF
view s.ibv --iso 1000.5 --size 320x240 --lod off --script pause.txt --stats pause.json \
    --exit-after 90
check "the paused run exits with 0 (got $rc: $err)" test "$rc" = 0
surface=$(pct_differ paused-view.png bg.png)
check "paused, a new view still shows the surface (${surface:-?} % of the pixels)" \
    awk -v p="${surface:-0}" 'BEGIN { exit !(p >= 5) }'
same_image "paused, a new isovalue shows its surface" paused-iso.png r-camera.png
check "two passes: the first view, then the new isovalue" grep -q '"passes": 2,' pause.json
# clipping: the window with --clip shows isorender's clipped image; clip off shows the whole
# surface (a new pass), clip on the clipped one again; without planes, clip is a message only
cat >clip.txt <<EOF
overlay off
wait done
screenshot clip-on.png
clip off
wait done
screenshot clip-off.png
clip on
wait done
screenshot clip-again.png
quit
EOF
view s.ibv --iso 1000.5 --size 320x240 --lod off --clip -x=63.5 --clip z=40 --script clip.txt \
    --stats clip.json --exit-after 90
check "the clipped run exits with 0 (got $rc: $err)" test "$rc" = 0
"$bin/isorender" s.ibv --iso 1000.5 --size 320x240 --view -y --lod off --clip -x=63.5 \
    --clip z=40 -o r-clip.png --quiet
same_image "the window with --clip shows isorender's clipped image" clip-on.png r-clip.png
same_image "clip off shows the whole surface" clip-off.png r-start.png
same_image "clip on shows the clipped one again" clip-again.png r-clip.png
check "the clipped and whole images differ (the test can fail)" \
    sh -c '! "$0" r-clip.png r-start.png --level 2 --max-pct 1 >/dev/null' "$compare"
check "three passes: clipped, whole, clipped" grep -q '"passes": 3,' clip.json
check "the statistics give the planes that applied at the end" grep -q '"clip": \[\[' clip.json
view s.ibv --iso 1000.5 --size 320x240 --lod off --script clip.txt --force --exit-after 90
check "without planes, clip changes nothing (got $rc: $err)" test "$rc" = 0
same_image "... the image stays the whole surface" clip-again.png r-start.png

printf 'pause maybe\n' >badpause.txt
expect_error 1 "badpause.txt:1" "$bin/isoview" s.ibv --iso 1 --script badpause.txt

# no script: --screenshot-at and --exit-after alone, adaptive resolution on (the default)
view s.ibv --iso 1500.5 --size 320x240 --cache-mb 1 --screenshot-at 0.5 at.png \
    --exit-after 2 --stats at.json --quiet
check "--exit-after exits with 0 (got $rc: $err)" test "$rc" = 0
check "after about 2 s (took ${elapsed} s)" test "$elapsed" -ge 2 -a "$elapsed" -le 30
check "--screenshot-at writes its image" test -s at.png
check "--quiet prints nothing" test -z "$out"
check "stats show rays" grep -q '"rays": [1-9]' at.json
check "stats say lod" grep -q '"lod": true' at.json
expect_error 1 "exists" "$bin/isoview" s.ibv --iso 1 --screenshot-at 1 at.png
# with adaptive resolution (the default), f extracts at the view's resolution: the window shows
# isorender --full-lod's image, which the finished progressive pass equals; at a pixel error of
# 16 the coarse levels differ from level 0's full extraction in a few % of the pixels
printf 'overlay off\nwait done\nscreenshot %s\nfull\nwait done\nscreenshot %s\nquit\n' \
    lod-pass.png lod-full.png >lod.txt
view s.ibv --iso 1000.5 --size 320x240 --pixel-error 16 --script lod.txt --stats lod.json --quiet
check "f with adaptive resolution exits with 0 (got $rc: $err)" test "$rc" = 0
"$bin/isorender" s.ibv --iso 1000.5 --size 320x240 --view -y --pixel-error 16 --full-lod \
    -o r-lod.png --stats r-lod.json --quiet
same_image "... f shows --full-lod's image" lod-full.png r-lod.png
same_image "... as the finished pass does" lod-pass.png r-lod.png
check "--full-lod uses a coarse level only" grep -q '"level": 0, "bricks_touched": 0,' r-lod.json
check "the image differs from level 0's full extraction (the test can fail)" \
    sh -c '! "$0" r-lod.png r-start.png --level 2 --max-pct 0.2 >/dev/null' "$compare"
check "the statistics say full-lod" grep -q '"mode": "full-lod"' lod.json
check "and the lod they used" grep -q '"pixel_error": 16' lod.json
# --aa 4: a multisampled window (its screenshot differs from the one without at the edges)
printf 'overlay off\nfull\nwait done\nscreenshot %s\nquit\n' aa1.png >aa1.txt
printf 'overlay off\nfull\nwait done\nscreenshot %s\nquit\n' aa4.png >aa4.txt
view s.ibv --iso 1500.5 --size 320x240 --lod off --script aa1.txt --quiet
view s.ibv --iso 1500.5 --size 320x240 --lod off --aa 4 --script aa4.txt --quiet
check "--aa 4 opens a window and saves its image (got $rc: $err)" test -s aa4.png
check "--aa 4 changes the edges only" "$bin/tests/png_compare" aa1.png aa4.png --level 3 --max-pct 10
check "--aa 4 changes the edges" sh -c "! '$bin/tests/png_compare' aa1.png aa4.png"

# a corrupted brick file (4 KiB pages of payloads zeroed): the window closes with one line
# naming the file and the brick, exit 1, and neither the screenshot nor the statistics appear
cp s.ibv z.ibv
for off in 256 100000 200000 300000 400000 500000 600000 700000 800000 900000 1000000; do
    "$bin/tests/corrupt" inplace z.ibv "zero:$off:4096" || bad "corrupt inplace z.ibv at $off"
done
printf 'wait done\nscreenshot z.png\nquit\n' >z.txt
view z.ibv --iso 1000.5 --size 320x240 --script z.txt --stats z.json --exit-after 60
lines=$(printf '%s\n' "$err" | grep -c "^isoview:")
check "a corrupted brick ends isoview with exit 1 (got $rc)" test "$rc" = 1
check "with one line naming the file and the brick ($err)" \
    sh -c 'test "$0" = 1 && printf "%s" "$1" | grep -q "^isoview: z.ibv: brick [0-9]* (level"' \
    "$lines" "$err"
check "no screenshot of a wrong image" test ! -e z.png
check "no statistics" test ! -e z.json
finish
