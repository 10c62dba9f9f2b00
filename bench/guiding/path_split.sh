#!/bin/sh
# How much of a scene's error each kind of path carries, in bench's relMSE
# (0.1% of the pixels dropped) and in the full one (docs/guiding.md, "Glints",
# *Where env-spheres' error is, by path*). Builds a scratch copy of HEAD with
# path_split.patch: every vertex of a camera path gets a letter, D (a diffuse
# lobe), S (a smooth reflector: what glints serve), G (other glossy), X
# (delta), and the light collected at a vertex (its light samples, and what
# the ray leaving it finds) the letters up to it; IRIS_CAT=PAT leaves out
# (IRIS_CAT_MODE=1) or keeps only (=2) the light whose letters end in PAT
# (^PAT: are PAT). For each PAT it renders SEEDS seeds without that light and
# with it alone, and prints bench/guiding/seed_variance.py's lines: without it
# against the reference less its mean over the seeds (what the image's error
# would be if that light were free of noise), and alone against its own mean.
# With the guided methods training learns from the same split light, so their
# guide differs a little. The renders run with --connect off: the connections'
# light (the door, the sky rooms) carries no letters, and left in every
# render it would be counted twice against the reference less the part
# alone. The whole image's line comes with PAT "-".
# REF: a reference of the same size, e.g.
#   iris render env-spheres --method mis --sampler independent --spp 32768 \
#     --width 108 --height 72 --seed 999 --variance -o REF.exr
# The patch is against the commit that added it; on a later HEAD that no
# longer takes it, set SCRATCH_BASE to that commit.
# usage: bench/guiding/path_split.sh REF.exr SCENE SPP SEEDS METHOD PAT...
#   e.g. bench/guiding/path_split.sh REF.exr env-spheres 256 16 mis - DS DG GG
set -eu
[ $# -ge 6 ] || { sed -n '2,/^set -eu/p' "$0" | sed '$d'; exit 2; }
REF=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
SCENE=$2; SPP=$3; SEEDS=$4; M=$5
shift 5
REPO=$(cd "$(dirname "$0")/../.." && pwd)
# shellcheck source=bench/guiding/scratch_patch.sh
. "$REPO/bench/guiding/scratch_patch.sh"
scratch_build path_split.patch
render() { # PAT MODE TAG
  s=1
  while [ "$s" -le "$SEEDS" ]; do
    IRIS_CAT=$1 IRIS_CAT_MODE=$2 "$SCRATCH/build/tools/iris" render "$SCENE" --method "$M" --force-guiding --connect off \
      --spp "$SPP" --width 108 --height 72 --seed "$s" --threads 2 --quiet -o "$W/$3_$s.exr"
    s=$((s + 1))
  done
}
echo "== $SCENE, $M, $SPP spp, seeds 1-$SEEDS"
for pat in "$@"; do
  if [ "$pat" = - ]; then
    render "" 1 whole
    /usr/bin/python3 "$REPO/bench/guiding/seed_variance.py" "$REF" "$W/whole_*.exr" | sed 's/^/whole /'
    continue
  fi
  tag=$(printf '%s' "$pat" | tr '^' 'B')
  render "$pat" 1 "without_$tag"
  render "$pat" 2 "alone_$tag"
  /usr/bin/python3 "$REPO/bench/guiding/seed_variance.py" "$REF" "$W/without_${tag}_*.exr:$W/alone_${tag}_*.exr" \
    "$W/alone_${tag}_*.exr:self" | sed "s/^/$pat /"
done
