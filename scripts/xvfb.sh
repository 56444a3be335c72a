# Sourced by the scripts that run the viewer without a display: `xvfb COMMAND...` runs COMMAND
# under `xvfb-run -a` with a 1024x768x24 screen and returns COMMAND's exit code.
# The X authority file is ours (-f): xvfb-run's own temporary directory can fail to be removed
# at exit (Debian's xvfb-run then exits 5, "problem while cleaning up temporary directory",
# whatever COMMAND returned; seen in CI), and with -f it makes none.
xvfb() {
  local auth rc=0
  auth=$(mktemp "${TMPDIR:-/tmp}/jello-xauth.XXXXXX")
  xvfb-run -a -f "$auth" -s "-screen 0 1024x768x24" "$@" || rc=$?
  rm -f "$auth"
  return "$rc"
}
