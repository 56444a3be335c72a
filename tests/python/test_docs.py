"""The documents hold together: every relative link of every Markdown file in the project
resolves to a file that exists, and every #anchor to a heading of its target (GitHub's anchors),
so that moving a section or a file cannot leave a dangling reference behind; the README stays a
screen or two (under 250 lines) and starts with the two commands."""
import pathlib
import re
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]


def documents():
    listed = subprocess.run(["git", "ls-files", "-co", "--exclude-standard", "*.md"], cwd=ROOT,
                            check=True, capture_output=True, text=True).stdout.split()
    return [ROOT / p for p in listed if (ROOT / p).exists()]


def anchors(path):
    text = re.sub(r"```.*?```", "", path.read_text(), flags=re.S)
    out = set()
    for title in re.findall(r"^#{1,6} (.*)$", text, re.M):
        a = re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")
        out.add(a)
    return out


def links(path):
    text = re.sub(r"```.*?```", "", path.read_text(), flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    return re.findall(r"\[[^\]]*\]\(([^)\s]+)\)", text)


def test_every_relative_link_and_anchor_resolves():
    broken = []
    for doc in documents():
        for target in links(doc):
            if re.match(r"[a-z]+:", target):
                continue
            path, _, fragment = target.partition("#")
            dest = (doc.parent / path).resolve() if path else doc
            if not dest.exists():
                broken.append(f"{doc.relative_to(ROOT)}: {target} (no such file)")
            elif fragment and dest.suffix == ".md" and fragment not in anchors(dest):
                broken.append(f"{doc.relative_to(ROOT)}: {target} (no such heading)")
    assert broken == []


def test_the_readme_is_short_and_starts_with_the_two_commands():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) < 250
    head = "\n".join(text.splitlines()[:20])
    assert "scripts/run.sh" in head and "scripts/test.sh" in head
