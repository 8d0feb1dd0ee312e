#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Every command of the README runs (issue 12, item 6): the ```sh blocks in order, in one scratch
# folder holding data/, examples/ and build/ of this tree; the error example compares its
# message line for line; the L-Py model block is grown; the C block is compiled against the
# library and run. Counts are scaled down so the suite stays fast (the table below); make
# targets are checked with a dry run (CI runs them: .ci/run) and `make demo` runs its script.
# Usage: cli_readme_test.sh VERDANT_BINARY SOURCE_DIR
source "$(dirname "$0")/cli_lib.sh" readme "$@"
BUILD=$(cd "$(dirname "$V")" && pwd)
cd "$T" || exit 1
ln -s "$SRC/data" data
ln -s "$SRC/examples" examples
ln -s "$SRC/scripts" scripts
mkdir build
ln -s "$V" build/verdant
[ -d "$BUILD/python" ] && ln -s "$BUILD/python" build/python

python3 - "$SRC" "$BUILD" "$T" <<'PY'
import json, os, re, shutil, subprocess, sys

src, build, t = sys.argv[1:4]
readme = open(os.path.join(src, "README.md")).read()
passed = failed = 0

def report(ok, name, why=""):
    global passed, failed
    if ok:
        passed += 1
        print("ok   " + name)
    else:
        failed += 1
        print("FAIL " + name + (" (" + why[-600:] + ")" if why else ""))

# a command that runs past the limit is a failure, reported as such (the sanitizer build, ten to
# thirty times slower, sets a longer limit through VD_TEST_TIMEOUT)
LIMIT = float(os.environ.get("VD_TEST_TIMEOUT", "600"))

def run(cmd, timeout=None):
    try:
        return subprocess.run(["bash", "-c", cmd], cwd=t, capture_output=True, text=True,
                              timeout=timeout or LIMIT)
    except subprocess.TimeoutExpired as e:
        return subprocess.CompletedProcess(e.cmd, 124, "", f"timed out after {e.timeout:.0f} s")

# sizes cut for the test: the README's commands as written, smaller
SCALE = [(r"--count 1000\b", "--count 2"), (r"--count 100\b", "--count 2"), (r"--images 4\b", "--images 1"),
         (r"--points 1000000\b", "--points 20000"), (r"--points 100000\b", "--points 5000"),
         (r"--episodes 20\b", "--episodes 2")]

blocks = re.findall(r"^```([a-z]*)\n(.*?)^```", readme, re.S | re.M)
report(len(blocks) >= 8, "README has its code blocks", str(len(blocks)))
ffmpeg = shutil.which("ffmpeg") is not None
for kind, body in blocks:
    lines = body.split("\n")
    if kind == "sh":
        for i, line in enumerate(lines):
            cmd = line.split("  #")[0].strip() if not line.startswith("PYTHONPATH") else line.strip()
            if not cmd or cmd.startswith("#"):
                continue
            if cmd.startswith("make"):
                # a target of the Makefile, run by CI (.ci/run) or here (demo)
                r = run(f"make -n -C {src} {cmd[4:].strip()} >/dev/null")
                report(r.returncode == 0, "make target: " + cmd, r.stderr)
                if cmd.split()[:2] == ["make", "demo"]:
                    r = run("bash scripts/demo.sh ./build/verdant")
                    report(r.returncode == 0 and os.path.exists(os.path.join(t, "out/tomato.png")) or
                           "no OpenGL" in r.stderr + r.stdout, "make demo's script", r.stderr + r.stdout)
                continue
            if cmd.startswith("PYTHONPATH"):
                if not os.path.isdir(os.path.join(t, "build/python")) or not os.path.exists("/usr/bin/python3"):
                    print("skip " + cmd + " (no python package built)")
                    continue
                # a sanitizer build preloads its runtimes into the interpreter (CMakeLists.txt)
                r = run((os.environ.get("VD_README_PYENV", "") + " " + cmd).strip())
                want = lines[i + 1].split("# prints: ")[1].split("   ")[0] if i + 1 < len(lines) and "# prints:" in lines[i + 1] else None
                report(r.returncode == 0 and (want is None or r.stdout.strip() == want), cmd[:70], r.stderr + r.stdout)
                continue
            for a, b in SCALE:
                cmd = re.sub(a, b, cmd)
            r = run(cmd)
            if "--mp4" in cmd and not ffmpeg:
                # without ffmpeg the video is skipped with a message (exit 1)
                report(r.returncode == 1 and "skipped" in r.stderr, cmd, r.stderr)
            elif "no EGL display" in r.stderr or "no OpenGL context" in r.stderr:
                print("skip " + cmd + " (no OpenGL context)")
            else:
                report(r.returncode == 0, cmd, r.stderr)
            # what the README says of the pull: its calyx breaks at 1.5 N
            if "--pull fruit=0,0.5,-3" in cmd and r.returncode == 0:
                events = open(os.path.join(t, "run/events.csv")).read().split("\n")[1].split(",")
                report(events[6] == "fruit" and abs(float(events[7]) - 1.5) < 0.05,
                       "the pull example's calyx breaks at 1.5 N", ",".join(events))
    elif kind == "" and lines[0].startswith("$ "):
        # an error example: the command and its message, line for line; nothing written
        r = run(lines[0][2:] + " 2>&1")
        want = "\n".join(l for l in lines[1:] if l)
        report(r.returncode == 2 and r.stdout.strip() == want, lines[0], r.stdout)
        out = lines[0].split("-o ")[1].split()[0] if "-o " in lines[0] else None
        report(out is None or not os.path.exists(os.path.join(t, out)), "no output after the error")
    elif kind == "python" and "Axiom:" in body:
        # the L-Py model of the README grows
        open(os.path.join(t, "readme_model.lpy"), "w").write(body)
        r = run("./build/verdant grow readme_model.lpy --stats")
        ok = r.returncode == 0
        if ok:
            d = json.loads(r.stdout)
            ok = d["labels"].get("fruit") == 1 and d["labels"].get("leaf") == 6
        report(ok, "the README's L-Py model grows", r.stderr + r.stdout[:300])
    elif kind == "c":
        # the library example compiles against the built library and runs (from the source tree)
        # the model's size is printed before the example frees everything (the sanitizer build
        # checks that it leaks nothing)
        prog = body.split("\n", 1)
        main = prog[1].replace("vd_data_destroy(d);", "nseg = m->nseg;\nvd_data_destroy(d);", 1)
        code = prog[0] + "\n#include <stdio.h>\nint main(void) {\nint nseg = 0;\n" + main + \
            "  printf(\"%d segments\\n\", nseg);\n  return nseg > 0 ? 0 : 1;\n}\n"
        open(os.path.join(t, "readme.c"), "w").write(code)
        # the link flags of the pkg-config file (verdant.pc), with the library of this build
        cflags = os.environ.get("VD_README_CFLAGS", "")
        r = run(f"cc -std=c11 {cflags} -I{src}/include readme.c {build}/libverdant.a "
                f"$(PKG_CONFIG_PATH={build} pkg-config --libs --static verdant | sed 's/-lverdant//') -o readme_c")
        report(r.returncode == 0, "the README's C example compiles", r.stderr)
        if r.returncode == 0:
            r = run("./readme_c")
            report(r.returncode == 0, "the README's C example runs", r.stderr + r.stdout)
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
PY
