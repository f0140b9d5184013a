#!/usr/bin/env bash
# A manual check of the glTF export (not run by cargo test): renders a .glb
# or .gltf with three.js's GLTFLoader in headless Chromium and saves a PNG.
#
#   tests/tools/screenshot-gltf.sh MODEL.glb OUT.png [WIDTHxHEIGHT] [SECONDS]
#
# SECONDS poses the "build" animation at that time; without it every piece
# is in place. Needs Debian's chromium (apt-get install -y chromium) and
# three.js (npm install three), found in $THREE_DIR, ./node_modules/three or
# /tmp/three/node_modules/three. Example, from the repository root:
#
#   cargo run --release --example export_gltf -- fixtures/house.obj /tmp/house --slopes
#   tests/tools/screenshot-gltf.sh /tmp/house/house.glb /tmp/house.png
#   tests/tools/screenshot-gltf.sh /tmp/house/house-exploded.glb /tmp/house-exploded.png
#
# The page is served over a local HTTP server (python3), since browsers do
# not load ES modules from file:// URLs.
set -euo pipefail

if [ $# -lt 2 ]; then
    echo "usage: $0 MODEL.glb OUT.png [WIDTHxHEIGHT] [SECONDS]" >&2
    exit 2
fi
model=$(realpath "$1")
out=$(realpath -m "$2")
size=${3:-1000x750}
time=${4:-}
here=$(cd "$(dirname "$0")" && pwd)

three=${THREE_DIR:-}
for candidate in "$three" ./node_modules/three /tmp/three/node_modules/three; do
    if [ -n "$candidate" ] && [ -f "$candidate/build/three.module.js" ]; then
        three=$(realpath "$candidate")
        break
    fi
done
if [ ! -f "$three/build/three.module.js" ]; then
    echo "three.js not found: npm install three, or set THREE_DIR" >&2
    exit 2
fi

site=$(mktemp -d)
trap 'kill "$server" 2>/dev/null || true; rm -rf "$site"' EXIT
cp "$here/screenshot-gltf.html" "$site/index.html"
ln -s "$three" "$site/three"
ext=${model##*.}
ln -s "$model" "$site/model.$ext"

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -m http.server "$port" --bind 127.0.0.1 --directory "$site" >/dev/null 2>&1 &
server=$!
for _ in $(seq 50); do
    if python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/')" 2>/dev/null; then
        break
    fi
    sleep 0.1
done

url="http://127.0.0.1:$port/index.html?model=model.$ext"
if [ -n "$time" ]; then
    url="$url&t=$time"
fi
chromium --headless --no-sandbox --disable-gpu --use-angle=swiftshader --enable-unsafe-swiftshader \
    --hide-scrollbars --window-size="${size/x/,}" --virtual-time-budget=20000 \
    --screenshot="$out" "$url" 2>/dev/null
echo "wrote $out"
