#!/usr/bin/env python3
"""No input aborts dyad (issue #40): a corpus of malformed graph files, each run through the real
`dyad validate` and `dyad run`, with and without a `--set`, and through the study, sweep and
training file loaders (`dyad study plan`, `dyad sweep --dry-run`, `dyad train`), with study and
sweep files of the wrong shapes too. Every command
must refuse the input with an exit code in 1..127 (never a signal: 134 is std::terminate's abort
after an uncaught exception, 139 a crash), and its error output must name the file (or, for a
bad --set on a good file, the --set and the file). Prints every failure and exits 1; exits 0 when
there is none.

    malformed_input_test.py DYAD_EXE WORK_DIR
"""
import os
import pathlib
import random
import shutil
import subprocess
import sys

# A graph every built-in plugin set validates (tests/graph_validation_test.cpp's): the corpus
# breaks it one way per file.
VALID = """graph: ok
clock: stepped
components:
  src:
    type: counter_source
    rate_hz: 10
    params: {noise: 1}
    outputs: {out: count}
  sink:
    type: counter_sink
    trigger: in
    inputs: {in: count}
"""

# A --set that is fine on VALID: with it, a malformed file goes through the --set path too (the
# path that aborted with YAML::InvalidNode, exit 134).
GOOD_SET = "src.noise=2"


def garbage():
    rng = random.Random(40)  # the same bytes on every run
    return bytes(rng.randrange(256) for _ in range(512))


def corpus():
    """(name, bytes of the graph file, extra files {name: text}) for each malformed kind."""
    v = VALID
    files = [
        ("syntax_error", "components: {a: [1, 2}\n"),
        ("tab_indentation", v.replace("  sink:\n    type", "  sink:\n\ttype")),
        ("cut_in_flow_mapping", v[: v.index("{noise: 1}") + len("{noise: 1")]),
        ("cut_in_block", v[: v.index("rate_hz") + 3]),
        ("cut_in_quoted_string", v.replace("type: counter_sink", 'type: "counter_si')[: v.index("counter_sink") + 10]),
        ("duplicate_key", v + "  src:\n    type: counter_source\n"),
        ("wrong_type", v.replace("rate_hz: 10", "rate_hz: fast")),
        ("unknown_key", "colour: red\n" + v),
        ("undefined_alias", v.replace("{noise: 1}", "*nowhere")),
        ("anchor_of_wrong_kind", v.replace("{noise: 1}", "&p {noise: 1}").replace("trigger: in", "trigger: *p")),
        ("binary_garbage", garbage()),
        ("empty_file", ""),
        ("not_a_mapping", "- a\n- b\n"),
        ("network_a_scalar", v + "network: 5\n"),
        ("network_a_list", v + "network: [a, b]\n"),
        ("components_a_scalar", "graph: ok\ncomponents: 3\n"),
        ("no_components", "graph: ok\nclock: stepped\n"),
        ("nested_too_deep", "graph: x\ncomponents: " + "[" * 3000 + "\n"),
        ("extends_missing_file", "extends: nowhere.yaml\n"),
        ("extends_malformed_base", "extends: base_cut.yaml\ncomponents: {src: {params: {noise: 2}}}\n"),
        ("extends_itself", "extends: extends_itself.yaml\n"),
        ("extends_a_list", "extends: [a.yaml]\n" + v),
        ("extends_a_folder", "extends: .\n" + v),
    ]
    extra = {"base_cut.yaml": v[: v.index("{noise: 1}") + 5]}
    return [(n, t.encode() if isinstance(t, str) else t) for n, t in files], extra


# --set texts that are wrong on VALID, a good file: each is refused naming the --set.
BAD_SETS = [
    "nobody.noise=1",                 # no such component
    "src.noise=[1,",                  # the value is not YAML
    "src.noise=fast",                 # the value has the wrong type
    "processes.robot.host=lab",       # the graph has no processes: (aborted: InvalidNode)
    "network.scope=5",
    "network=5",
    "components=3",
    "src.outputs.out.deeper=x",       # through a scalar
    "garbage",
    "=",
    "src.",
]


# Study and sweep files of the right YAML but the wrong shapes, beside good.yaml (VALID) and
# train.yaml (VALID too: not a training config): (command, file name, text). A study condition or a
# sweep --set into a section the graph lacks, and a training --set with a list index past 2^64,
# aborted before (YAML::InvalidNode, std::out_of_range).
STUDY = "study: s\ngraph: good.yaml\nparticipants: [P01]\n"
SHAPED = [
    ("study plan", "shapes_study.yaml", "study: s\ngraph: good.yaml\nparticipants: 5\nconditions: 3\n"),
    ("study plan", "kinds_study.yaml", "study: [s]\ngraph: {a: 1}\nparticipants: [[a]]\nconditions: {[a]: {src.noise: 2}}\n"),
    ("study plan", "set_study.yaml", STUDY + "conditions: {A: {processes.x.host: lab, '': 2, '=': 3}}\nrehearsal: [a]\n"),
    ("sweep", "shapes_sweep.yaml", "sweep: w\ngraph: good.yaml\nduration: 1\nruns: [5, [1], {a: 1}]\nseeds: {a: 1}\ntrain: 5\n"),
    ("sweep", "set_sweep.yaml", "sweep: w\ngraph: good.yaml\nduration: 1\ngrid: {src.noise: [[1], {a: 1}]}\n"
                                "set: {processes.a.host: lab}\n"),
    ("sweep", "study_sweep.yaml", "sweep: w\nstudy: set_study.yaml\ncondition: A\nduration: 1\ngrid: {src.noise: [1]}\n"),
    ("sweep", "train_sweep.yaml", "sweep: w\ngraph: good.yaml\nduration: 1\ngrid: {src.noise: [1]}\n"
                                  "train: {config: train.yaml, model: src.noise, set: {layers.99999999999999999999.d: 1}}\n"),
]


def run(cmd, cwd):
    try:
        p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=60)
    except subprocess.TimeoutExpired:
        return None, "", "timed out after 60 s"
    return p.returncode, p.stdout.decode(errors="replace"), p.stderr.decode(errors="replace")


def check(failures, what, cmd, cwd, must_name):
    rc, out, err = run(cmd, cwd)
    said = out + err
    if rc is None or rc < 0 or rc >= 128 or rc == 0:
        got = f"killed by signal {-rc} (a shell's exit {128 - rc})" if rc is not None and rc < 0 else f"exit {rc}"
        failures.append(f"{what}: {got}, want an exit in 1..127\n  $ {' '.join(cmd)}\n{said.strip()[:800]}")
        return
    missing = [m for m in must_name if m not in said]
    if missing or "terminate called" in said:
        failures.append(f"{what}: the error does not name {missing or 'the file'}\n  $ {' '.join(cmd)}\n{said.strip()[:800]}")


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        return 2
    dyad, work = os.path.abspath(sys.argv[1]), pathlib.Path(sys.argv[2])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    files, extra = corpus()
    for name, text in extra.items():
        (work / name).write_text(text)
    failures = []
    commands = 0
    for name, data in files:
        path = work / (name + ".yaml")
        path.write_bytes(data)
        f = str(path)
        for sets in ([], ["--set", GOOD_SET]):
            for cmd in (["validate", f], ["run", f, "--duration", "1", "--quiet"]):
                check(failures, f"{name}: {' '.join(cmd[:1] + sets)}", [dyad] + cmd + sets, work, [f])
                commands += 1
        # The tools' own YAML files go through the same YAML reader: the same bytes as a study,
        # a sweep and a training config.
        for cmd in (["study", "plan", f], ["sweep", f, "--dry-run", "-o", str(work / "sweep-out")],
                    ["train", f], ["train", f, "--set", "epochs=3"]):
            check(failures, f"{name}: {' '.join(cmd[:2])}", [dyad] + cmd, work, [f])
            commands += 1
    good = work / "good.yaml"
    good.write_text(VALID)
    for s in BAD_SETS:
        for cmd in (["validate", str(good)], ["run", str(good), "--duration", "1", "--quiet"]):
            check(failures, f"--set {s}: {cmd[0]}", [dyad] + cmd + ["--set", s], work, [str(good), "--set "])
            commands += 1
    (work / "train.yaml").write_text(VALID)
    for command, name, text in SHAPED:
        (work / name).write_text(text)
    for command, name, _ in SHAPED:
        extra = ["--dry-run", "-o", str(work / "sweep-out")] if command == "sweep" else []
        check(failures, f"{name}: {command}", [dyad] + command.split() + [str(work / name)] + extra, work, [name])
        commands += 1
    # A file that is not there, and a folder where a file is expected.
    for f in (str(work / "missing.yaml"), str(work)):
        for cmd in (["validate", f], ["validate", f, "--set", GOOD_SET], ["run", f, "--set", GOOD_SET]):
            check(failures, f"{f}: {cmd[0]}", [dyad] + cmd, work, [f])
            commands += 1
    for failure in failures:
        print("FAIL " + failure + "\n")
    print(f"{commands} commands on {len(files)} malformed files, {len(BAD_SETS)} bad --sets and {len(SHAPED)} study and sweep files: "
          f"{len(failures)} failure{'s' if len(failures) != 1 else ''}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
