#!/usr/bin/env bash
# The README's pictures, rendered again with the README's own commands and compared byte for byte
# with the committed files (golden images). Usage:
#   docs/images/regenerate.sh [--bless] [FOOTPRINT_BINARY]
# Without --bless a changed image fails (exit 1) and its new version is left in a temporary folder
# to look at; with --bless the committed files are replaced: a changed picture is a reviewed
# decision, never an accident. The volumes are the repository's own (tests/data).
set -euo pipefail
cd "$(dirname "$0")/../.."
bless=0
if [ "${1:-}" = --bless ]; then bless=1; shift; fi
fp=${1:-target/release/footprint}
[ -x "$fp" ] || { echo "build first: cargo build --release -p footprint-harness"; exit 2; }
data=tests/data
out=$(mktemp -d)
# One line per picture: the file name, then the footprint arguments the README shows for it.
while IFS='|' read -r name cmd; do
  [ -n "$name" ] || continue
  eval "set -- $cmd"
  "$fp" "$@" --out "$out/$name" >/dev/null
done <<LIST
default-scene.png|render
headsq-default.png|render $data/headsq_64x64x93_int16_le.nhdr --view 180,-90,0 -s 256x256
headsq-colorbar.png|render $data/headsq_64x64x93_int16_le.nhdr --shading phong --view 30,20,0 -s 256x256 --colorbar
headsq-phong.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 180,-90,0
headsq-iso.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading iso:1900 --view -30,-80,180
heart-texture.png|render $data/heart_32x32x12_float32_le.nhdr --tf density --shading texture --view 150,-20,180
view-+x.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --size 160x160 --view +x
view--x.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --size 160x160 --view -x
view-+y.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --size 160x160 --view +y
view--y.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --size 160x160 --view -y
view-+z.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --size 160x160 --view +z
view--z.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --size 160x160 --view -z
headsq-mip.png|render $data/headsq_64x64x93_int16_le.nhdr --view 180,-90,0 -s 256x256 --blend mip
headsq-crop.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 150,-70,0 --size 256x256 --crop 0:63,0:63,0:60
headsq-crop-clip.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 150,-70,0 --size 256x256 --crop 0:63,0:63,0:60 --clip 0,1,0,0
paraview-preset.png|render $data/headsq_64x64x93_int16_le.nhdr --tf docs/presets/ct-warm.json --shading phong --view 180,-90,0 --size 256x256
cool-to-warm.png|render $data/headsq_64x64x93_int16_le.nhdr --tf 'Cool to Warm' --view 30,20,0 --size 256x256
transparent-srgb.png|render $data/headsq_64x64x93_int16_le.nhdr --tf Grayscale --window 1200,4000 --view +x --size 192x192 --background transparent --gamma srgb
perspective-headsq-ortho.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 30,20,0 --size 256x256
post-headsq.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 30,20,0 --size 256x256 --classification post
post-trilinear-headsq.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 30,20,0 --size 256x256 --classification post --reconstruction trilinear
perspective-headsq-60.png|render $data/headsq_64x64x93_int16_le.nhdr --tf ct-bone-skin --shading phong --view 30,20,0 --size 256x256 --perspective 60
splat-gaussian-60-30-30.png|splat --spacing 60,30,30 --rotate-z 30 --rotate-x 20 --table 65
splat-bilinear-sheared.png|splat --kernel bilinear --spacing 40,40,40 --rotate-x 40 --rotate-y 35 --table 65
splat-bilinear-sheared-paper.png|splat --kernel bilinear --spacing 40,40,40 --rotate-x 40 --rotate-y 35 --table 65 --method paper
LIST
changed=0
for f in "$out"/*.png; do
  name=$(basename "$f")
  if cmp -s "$f" "docs/images/$name"; then
    echo "docs/images/$name: identical"
  elif [ "$bless" = 1 ]; then
    cp "$f" "docs/images/$name"
    echo "docs/images/$name: blessed (replaced)"
  else
    echo "docs/images/$name: CHANGED (new render in $f)"
    changed=1
  fi
done
[ "$changed" = 0 ] || { echo "README images differ: look at them, then run $0 --bless"; exit 1; }
rm -rf "$out"
