"""Write the program the README shows after the marker `<!-- program NAME -->` (the next
fenced code block) to a file, so that the README's legacy Fortran and C programs are the
ones meson test and tests/test_install.py compile and check.

Usage: python readme_program.py README.md NAME OUTPUT
"""

import sys
from pathlib import Path


def extract(readme: Path, name: str) -> str:
    """The code of the fenced block after `<!-- program name -->` in readme."""
    lines = readme.read_text().splitlines()
    try:
        at = lines.index(f"<!-- program {name} -->")
    except ValueError:
        raise SystemExit(f"{readme}: no '<!-- program {name} -->' marker") from None
    start = next(i for i in range(at + 1, len(lines)) if lines[i].startswith("```")) + 1
    end = next(i for i in range(start, len(lines)) if lines[i].startswith("```"))
    return "\n".join(lines[start:end]) + "\n"


if __name__ == "__main__":
    readme, name, output = sys.argv[1:4]
    Path(output).write_text(extract(Path(readme), name))
