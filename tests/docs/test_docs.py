"""The documentation against the program it documents (README.md, docs/, CHANGELOG.md,
bench/README.md):

- every relative link and image resolves, the file and its #anchor (GitHub's heading slugs);
- every subcommand and option that `subscan --help` and each subcommand's `--help` list appears
  in docs/cli.md, each option in the section of its own command;
- every key of the settings file that `--save-settings` writes appears in docs/settings.md's
  tables with its default;
- every example block of the README (a fence whose info string is `sh example` or
  `python example`) runs, on synthetic scans or the shared data (skipped with the reason
  without them).

Environment: SUBSCAN_EXECUTABLE (the CLI), SUBSCAN_SOURCE_DIR (the tree), PYTHONPATH for the
Python example, SUBSCAN_TEST_DATA or ../shared/data for examples that name real scans.
"""

import json
import math
import os
import re
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("SUBSCAN_SOURCE_DIR", Path(__file__).resolve().parents[2]))
EXECUTABLE = str(Path(os.environ.get("SUBSCAN_EXECUTABLE", SOURCE / "build/src/subscan")).resolve())
DOCUMENTS = sorted(
    [SOURCE / "README.md", SOURCE / "CHANGELOG.md", SOURCE / "bench/README.md"]
    + list((SOURCE / "docs").glob("*.md"))
)
FENCE = re.compile(r"^(```+|~~~+)(.*)$")


def without_code(text):
    """The text with fenced blocks and inline code spans blanked out (line numbers kept): links
    and headings inside code are not links and headings."""
    lines, fence = [], None
    for line in text.split("\n"):
        match = FENCE.match(line.strip())
        if fence is None and match:
            fence = match.group(1)
            lines.append("")
        elif fence is not None:
            if line.strip().startswith(fence):
                fence = None
            lines.append("")
        else:
            lines.append(re.sub(r"`+[^`]*`+", "``", line))
    return "\n".join(lines)


def slug(heading):
    """GitHub's anchor for a heading: lower case, markup and punctuation dropped, spaces to
    hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text
    text = text.replace("`", "").replace("*", "").strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path):
    """Every anchor of a Markdown file: headings (repeats numbered -1, -2, ... as GitHub does)."""
    seen, result = {}, set()
    for line in without_code_keep_headings(path.read_text(encoding="utf-8")):
        match = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if not match:
            continue
        base = slug(match.group(2))
        count = seen.get(base, 0)
        seen[base] = count + 1
        result.add(base if count == 0 else f"{base}-{count}")
    return result


def without_code_keep_headings(text):
    """Lines outside fenced blocks, inline code intact (headings keep their code's text)."""
    fence = None
    for line in text.split("\n"):
        match = FENCE.match(line.strip())
        if fence is None and match:
            fence = match.group(1)
        elif fence is not None:
            if line.strip().startswith(fence):
                fence = None
        else:
            yield line


def links(path):
    """(line number, target) of every link and image in a Markdown file."""
    text = without_code(path.read_text(encoding="utf-8"))
    for number, line in enumerate(text.split("\n"), 1):
        for match in re.finditer(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", line):
            yield number, match.group(1)


def test_the_documents_exist():
    names = {path.relative_to(SOURCE).as_posix() for path in DOCUMENTS}
    for required in ["README.md", "CHANGELOG.md", "docs/cli.md", "docs/settings.md"]:
        assert required in names, f"{required} is missing"
    # The front page stays a front page (issue 45): at most 250 lines.
    readme_lines = (SOURCE / "README.md").read_text(encoding="utf-8").count("\n")
    assert readme_lines <= 250, f"README.md has {readme_lines} lines (at most 250)"


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: p.relative_to(SOURCE).as_posix())
def test_every_relative_link_resolves(document):
    broken = []
    for number, target in links(document):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto: - not ours
            continue
        file_part, _, anchor = target.partition("#")
        resolved = (document.parent / file_part).resolve() if file_part else document
        where = f"{document.relative_to(SOURCE)}:{number}: {target}"
        if not resolved.exists():
            broken.append(f"{where} (no such file)")
        elif anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
            broken.append(f"{where} (no such heading)")
    assert not broken, "broken links:\n" + "\n".join(broken)


def run_help(*arguments):
    result = subprocess.run([EXECUTABLE, *arguments, "--help"], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    return result.stdout


def subcommands():
    listing = run_help().split("Subcommands:", 1)[1]
    return re.findall(r"^  (\S+)\s", listing, re.MULTILINE)


def options(help_text):
    """The long and short options of a --help text's Options section."""
    section = help_text.split("Options:", 1)[1]
    found = set()
    for line in section.split("\n"):
        match = re.match(r"^  (-\w)?,?(--[\w-]+)?", line)
        if match:
            found.update(name for name in match.groups() if name)
    return found


def cli_sections():
    """docs/cli.md's sections by command: the text under a heading that names `subscan NAME`."""
    text = (SOURCE / "docs/cli.md").read_text(encoding="utf-8")
    sections, current = {}, None
    for line in text.split("\n"):
        heading = re.match(r"^##\s+`?subscan ([\w-]+)", line)
        if heading:
            current = heading.group(1)
            sections[current] = ""
        elif re.match(r"^##\s", line):
            current = None
        elif current:
            sections[current] += line + "\n"
    return sections


def test_every_command_and_option_is_in_the_cli_page():
    sections = cli_sections()
    text = (SOURCE / "docs/cli.md").read_text(encoding="utf-8")
    missing = [f"`{name}` (subscan --help)" for name in options(run_help()) if f"`{name}`" not in text]
    names = subcommands()
    assert len(names) >= 10, f"subscan --help lists too few subcommands: {names}"
    for command in names:
        if command not in sections:
            missing.append(f"a section headed `subscan {command} ...`")
            continue
        # -h/--help, which every command takes, is documented once, with the global options.
        for option in sorted(options(run_help(command)) - {"-h", "--help"}):
            # An option counts where it is named in code, alone or with its value.
            if not re.search(r"`" + re.escape(option) + r"(?![\w-])[^`]*`", sections[command]):
                missing.append(f"{option} of `subscan {command}`")
    assert not missing, "docs/cli.md lacks:\n" + "\n".join(missing)


def test_every_help_ends_with_its_manual_pages():
    problems = []
    for command in [None] + subcommands():
        text = run_help(*([command] if command else []))
        last = [line for line in text.strip().split("\n") if line.strip()][-1]
        pages = re.findall(r"((?:docs|bench)/[\w./-]+\.md(?:#[\w-]+)?|README\.md)", last)
        name = command or "subscan"
        if not last.startswith("Manual:") or not pages:
            problems.append(f"{name}: --help ends with {last!r}, not with the manual's pages")
        if command and f"docs/cli.md#subscan-{command}" not in pages:
            problems.append(f"{name}: --help does not name docs/cli.md#subscan-{command}")
        for page in pages:
            file_part, _, anchor = page.partition("#")
            if not (SOURCE / file_part).exists():
                problems.append(f"{name}: --help names {page}, which does not exist")
            elif anchor and anchor not in anchors(SOURCE / file_part):
                problems.append(f"{name}: --help names {page}, a heading that does not exist")
    assert not problems, "\n".join(problems)


def saved_settings(tmp_path, settings=None):
    """The settings file --save-settings writes, from the defaults (or from `settings`)."""
    command = [EXECUTABLE, "render", "synthetic:sphere?points=500", "--width", "8", "--height",
               "8", "-o", str(tmp_path / "picture.png"), "--save-settings",
               str(tmp_path / "saved.json")]
    if settings is not None:
        (tmp_path / "in.json").write_text(json.dumps(settings))
        command += ["--settings", str(tmp_path / "in.json")]
    result = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    return json.loads((tmp_path / "saved.json").read_text())


def documented_defaults():
    """{key: default cell} of docs/settings.md's tables: rows whose first cell is `a.b`."""
    rows = {}
    for line in (SOURCE / "docs/settings.md").read_text(encoding="utf-8").split("\n"):
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if len(cells) >= 2 and re.fullmatch(r"`[\w.\[\]]+`", cells[0]):
            rows[cells[0].strip("`")] = cells[1]
    return rows


def same_value(documented, saved):
    """Whether a documented default (JSON in code, e.g. `0.2` or `[8.51, 5.57, 3.95]`) is the
    saved value. Floats compare within 1e-6 relative: the file holds float32 values printed as
    doubles (0.2 -> 0.20000000298023224)."""
    if isinstance(saved, bool) or saved is None or isinstance(saved, str):
        return documented == saved
    if isinstance(saved, list):
        return (isinstance(documented, list) and len(documented) == len(saved)
                and all(same_value(d, s) for d, s in zip(documented, saved)))
    return (isinstance(documented, (int, float)) and not isinstance(documented, bool)
            and math.isclose(documented, saved, rel_tol=1e-6, abs_tol=1e-12))


def flatten(settings, prefix=""):
    for key, value in settings.items():
        if isinstance(value, dict):
            yield from flatten(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", value


def test_every_setting_is_in_the_settings_page_with_its_default(tmp_path):
    defaults = dict(flatten(saved_settings(tmp_path)))
    # A directional light's keys exist only in a list entry: save one written as {}.
    light = saved_settings(tmp_path, {"shading": {"lights": [{}]}})["shading"]["lights"][0]
    defaults.update({f"shading.lights[].{key}": value for key, value in light.items()})
    assert len(defaults) > 40, "the settings file holds too few keys; was it read right?"
    documented = documented_defaults()
    problems = []
    for key, value in sorted(defaults.items()):
        if key not in documented:
            problems.append(f"{key}: not in a table row of its own")
            continue
        cell = documented[key].strip()
        code = re.fullmatch(r"`([^`]*)`", cell)
        try:
            parsed = json.loads(code.group(1)) if code else None
        except json.JSONDecodeError:
            parsed = None
        if not code or not same_value(parsed, value):
            problems.append(f"{key}: documented default {cell}, saved {json.dumps(value)}")
    assert not problems, "docs/settings.md:\n" + "\n".join(problems)


def example_blocks():
    """(language, first line number, text) of the README's example fences."""
    lines = (SOURCE / "README.md").read_text(encoding="utf-8").split("\n")
    blocks, current = [], None
    for number, line in enumerate(lines, 1):
        match = FENCE.match(line.strip())
        if current is None and match:
            words = match.group(2).split()
            marked = len(words) == 2 and words[1] == "example" and words[0] in ("sh", "python")
            current = (words[0] if marked else "other", number + 1, [])
        elif current is not None and match and not match.group(2):
            if current[0] != "other":
                blocks.append((current[0], current[1], "\n".join(current[2])))
            current = None
        elif current is not None:
            current[2].append(line)
    return blocks


def data_directory():
    candidates = [os.environ.get("SUBSCAN_TEST_DATA"), SOURCE.parent / "shared" / "data"]
    for candidate in candidates:
        if candidate and Path(candidate).is_dir():
            return Path(candidate)
    return None


def prepared_directory(tmp_path):
    """A working directory in which the shared data's files appear under their own names, so an
    example can name `bun_zipper.ply` as a user would name their file."""
    data = data_directory()
    if data is not None:
        for entry in data.iterdir():
            (tmp_path / entry.name).symlink_to(entry)
    return data


def commands_of(block):
    """The shell block's commands, continuation lines joined, comments dropped."""
    joined = block.replace("\\\n", " ")
    for line in joined.split("\n"):
        line = line.split(" #")[0].strip()
        if line and not line.startswith("#"):
            yield line


EXAMPLES = example_blocks()


def test_the_readme_has_examples():
    assert any(language == "sh" for language, _, _ in EXAMPLES), "no `sh example` block"


@pytest.mark.parametrize("example", EXAMPLES, ids=[f"README.md:{e[1]}" for e in EXAMPLES])
def test_every_readme_example_runs(example, tmp_path):
    language, line, block = example
    data = prepared_directory(tmp_path)
    environment = dict(os.environ)
    # The examples run in a folder of their own: the module's path must not be relative.
    environment["PYTHONPATH"] = os.pathsep.join(
        str(Path(entry).resolve()) for entry in environment.get("PYTHONPATH", "").split(os.pathsep)
        if entry)
    if language == "python":
        result = subprocess.run([sys.executable, "-c", block], cwd=tmp_path, env=environment,
                                capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, f"README.md:{line}: {result.stderr}"
        return
    for command in commands_of(block):
        words = shlex.split(command)
        assert words[0] == "subscan", f"README.md:{line}: an example runs subscan, not {words[0]}"
        scans = [word for word in words[2:3] if not word.startswith(("-", "synthetic:"))]
        if scans and not (tmp_path / scans[0]).exists():
            if data is None:
                pytest.skip(f"README.md:{line}: {scans[0]} needs ../shared/data or "
                            "$SUBSCAN_TEST_DATA, which this machine lacks")
        result = subprocess.run([EXECUTABLE, *words[1:]], cwd=tmp_path, env=environment, capture_output=True,
                                text=True, timeout=600)
        assert result.returncode == 0, f"README.md:{line}: `{command}` failed: {result.stderr}"
