#!/usr/bin/env bash
# Builds the installable QGIS plugin zip:  scripts/package.sh [OUTPUT.zip]   (default lidarphoto.zip)
#
# The zip holds one top folder `lidarphoto/` with the files git knows about (tracked, plus
# untracked ones that are not ignored), minus every path marked `export-ignore` in
# .gitattributes - the same content as `git archive --prefix=lidarphoto/ HEAD` once committed,
# but also right for a work tree with uncommitted files. Changes nothing in git.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
OUT=${1:-lidarphoto.zip}
PY=$(command -v python3 || command -v /usr/bin/python3)
git rev-parse --is-inside-work-tree >/dev/null 2>&1 || { echo "package.sh: not a git work tree" >&2; exit 2; }

"$PY" - "$OUT" <<'PY'
import configparser
import os
import stat
import subprocess
import sys
import tempfile
import zipfile

PREFIX = "lidarphoto/"
out = os.path.abspath(sys.argv[1])

files = subprocess.run(
    ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
    check=True, capture_output=True,
).stdout.split(b"\0")
files = sorted({f for f in files if f})
attrs = subprocess.run(
    ["git", "check-attr", "-z", "--stdin", "export-ignore"],
    input=b"\0".join(files) + b"\0", check=True, capture_output=True,
).stdout.split(b"\0")
ignored = {attrs[i] for i in range(0, len(attrs) - 2, 3) if attrs[i + 2] == b"set"}

keep = []
for raw in files:
    path = raw.decode("utf-8", "surrogateescape")
    if raw in ignored or not os.path.isfile(path) or os.path.islink(path):
        continue
    if os.path.abspath(path) == out:
        continue
    if path.startswith("i18n/") and path.endswith(".qm"):
        continue  # built below from the .ts, never a stale local copy
    keep.append(path)

for required in ("metadata.txt", "__init__.py", "LICENSE"):
    if required not in keep:
        sys.exit(f"package.sh: {required} is missing from the package")
meta = configparser.ConfigParser()
meta.read("metadata.txt", encoding="utf-8")
version = meta.get("general", "version")
unset = [k for k in ("email", "homepage", "repository", "tracker")
         if not meta.get("general", k, fallback="").strip()]
if unset:  # the zip installs; plugins.qgis.org refuses an upload without them
    print(f"package.sh: warning: metadata.txt has no {', '.join(unset)} yet "
          "(needed before an upload to plugins.qgis.org)", file=sys.stderr)

# the compiled translations (lrelease): QGIS loads the .qm, the core reads the .ts
qm_dir = tempfile.mkdtemp(prefix="lidarphoto-qm-")
r = subprocess.run([sys.executable, "scripts/i18n.py", "--qm", qm_dir], capture_output=True, text=True)
if r.returncode != 0:
    sys.exit(f"package.sh: cannot build the translations:\n{r.stdout}{r.stderr}")
built = {f"i18n/{name}": os.path.join(qm_dir, name) for name in sorted(os.listdir(qm_dir))}
keep = sorted(keep + list(built))

tmp = out + ".part"
with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
    seen_dirs = set()
    for path in keep:
        parts = path.split("/")[:-1]
        for i in range(len(parts) + 1):
            d = PREFIX + "".join(part + "/" for part in parts[:i])
            if d not in seen_dirs:
                seen_dirs.add(d)
                info = zipfile.ZipInfo(d, date_time=(2020, 1, 1, 0, 0, 0))
                info.external_attr = (stat.S_IFDIR | 0o755) << 16 | 0x10
                zf.writestr(info, b"")
        source = built.get(path, path)
        info = zipfile.ZipInfo(PREFIX + path, date_time=(2020, 1, 1, 0, 0, 0))
        mode = 0o755 if os.stat(source).st_mode & stat.S_IXUSR else 0o644
        info.external_attr = (stat.S_IFREG | mode) << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        with open(source, "rb") as fh:
            zf.writestr(info, fh.read())
os.replace(tmp, out)
for path in built.values():
    os.remove(path)
os.rmdir(qm_dir)
print(f"{out}: lidarphoto {version}, {len(keep)} files")
PY
