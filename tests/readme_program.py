"""The fenced code blocks of README.md (or any Markdown page), so that tests run exactly
what a reader copies: tests/test_readme.py runs the commands and the Python example, and
tests/test_install.py the block that builds and links the Fortran and C examples.

Usage: python readme_program.py README.md   (lists the blocks: index, language, lines)
"""

import sys
from dataclasses import dataclass
from pathlib import Path


@dataclass
class Block:
    """One fenced block: its info string (``sh``, ``python``, ...), its text and the line
    of the file it starts on (1-based, the opening fence)."""

    lang: str
    code: str
    line: int


def blocks(page: Path) -> list[Block]:
    """Every fenced (```) block of page, in order; an unclosed fence is an error."""
    lines = Path(page).read_text().splitlines()
    out, i = [], 0
    while i < len(lines):
        if lines[i].startswith("```"):
            lang, start = lines[i][3:].strip(), i
            try:
                end = next(j for j in range(i + 1, len(lines)) if lines[j].startswith("```"))
            except StopIteration:
                raise SystemExit(f"{page}:{start + 1}: fenced block never closed") from None
            out.append(Block(lang, "\n".join(lines[i + 1:end]) + "\n", start + 1))
            i = end
        i += 1
    return out


def commands(block: Block) -> list[str]:
    """The shell commands of a block: its lines without comments and blank lines."""
    out = []
    for line in block.code.splitlines():
        cmd = line.split("#", 1)[0].strip() if not line.lstrip().startswith("#!") else ""
        if cmd:
            out.append(cmd)
    return out


if __name__ == "__main__":
    for k, b in enumerate(blocks(Path(sys.argv[1]))):
        print(k, b.lang, f"line {b.line}", len(b.code.splitlines()), "lines")
