#!/bin/sh
# xc_look.sh - the appearance cross-check: every POV-Ray 3.7 distribution example in
# textures/, lights/, camera/ and interior/ (with their subdirectories;
# camera/mesh_camera is the parser's: tests/test_sdl_lang.c), advanced/diffract.pov, incdemo/glasses/glass.pov and
# qtvr/qtvrpanorama.pov (where installed), rendered at 160x120 by partray and by
# povray, compared as scripts/xc_shapes.py does (mean absolute sRGB
# difference after a 4x4 downsample, agreement <= 0.02; a scene counts as
# supported when partray warns of nothing it skipped in it).
#
# Usage: scripts/xc_look.sh [--partray PATH] [--out DIR] [--jobs N] [--size WxH]
# (options are passed to xc_shapes.py). Prints one line per scene and the
# fraction of supported scenes that agree.
here=$(dirname "$0")
scenes=/usr/share/povray-3.7/scenes
# examples elsewhere that use appearance features (irid, dispersion) and
# the panorama example Debian ships apart from the scenes
extra="$scenes/advanced/diffract.pov $scenes/incdemo/glasses/glass.pov"
qtvr=/usr/share/doc/povray/examples/qtvr/qtvrpanorama.pov
[ -f "$qtvr" ] && extra="$extra $qtvr"
list=$( (for d in textures lights camera interior; do find -L "$scenes/$d" -name '*.pov'; done | grep -v /mesh_camera/; echo "$extra") | sort)
exec python3 "$here/xc_shapes.py" --out xc_look_out "$@" $list
