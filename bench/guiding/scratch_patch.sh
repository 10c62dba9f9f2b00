# Sourced by the prototype benchmarks (connect_ab.sh, last_vertices_split.sh, path_split.sh,
# light_trace_ab.sh, sky_connect_ab.sh, variance_aware_ab.sh,
# vertex_cache_ab.sh): scratch_build PATCH builds a throw-away copy of HEAD
# (or of SCRATCH_BASE, the commit a patch was made against) with
# bench/guiding/PATCH applied (iris and relmse, Release) and sets
# SCRATCH to its source directory (the build in $SCRATCH/build) and W to a
# temporary directory for the caller's files; both go when the shell exits.
# The scratch copy is a git worktree, which has no origin to find ../shared
# from, so the build is pointed at this repository's (or $IRIS_SHARED_DIR).
# REPO must be set to the repository.
# shellcheck shell=sh
scratch_build() {
  W=$(mktemp -d)
  SCRATCH=$W/src
  trap 'git -C "$REPO" worktree remove --force "$SCRATCH" >/dev/null 2>&1; rm -rf "$W"' EXIT
  git -C "$REPO" worktree add -f --detach "$SCRATCH" "${SCRATCH_BASE:-HEAD}" >/dev/null
  git -C "$SCRATCH" apply "$REPO/bench/guiding/$1"
  IRIS_SHARED_DIR=${IRIS_SHARED_DIR:-$REPO/../shared} cmake -S "$SCRATCH" -B "$SCRATCH/build" \
    -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build "$SCRATCH/build" -j2 --target iris relmse > /dev/null
}
