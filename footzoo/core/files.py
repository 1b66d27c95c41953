"""What is wrong with a file before it is parsed: a missing path or a link loop, a foreign text encoding, NUL bytes.

Used where footzoo opens a file a user named (recordings, YAML files, output paths), so that the
message names the real problem instead of the parser's symptom:

* a path that does not exist because it is a **symbolic link** to nothing, or a **loop** of links
  (``a.csv -> b.csv -> a.csv``), is named as such (not "no such file");
* **UTF-16 or UTF-32 text** (Windows "Unicode text", some loggers' exports) is named with the
  conversion to UTF-8, footzoo's text encoding (a UTF-8 byte-order mark is fine);
* **NUL bytes**: a file that starts with them, or has a run of them in the middle, was damaged
  while it was written (a logger that pre-allocates its file, a power cut, a full card); NULs
  only at the end are padding (:func:`nul_padding`), which a reader may drop, saying so.

And a file's SHA-256 (:func:`sha256`), read in blocks, for the hashes footzoo keeps of what it wrote or read.
"""

from __future__ import annotations

import codecs
import hashlib
import os
from pathlib import Path

#: Byte-order marks of the encodings footzoo does not read, longest first (UTF-32 LE starts like UTF-16 LE).
FOREIGN_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"), (codecs.BOM_UTF16_LE, "UTF-16"),
                (codecs.BOM_UTF16_BE, "UTF-16"))
#: Bytes of a file's start that :func:`foreign_encoding` looks at.
SNIFF_BYTES = 4096


def nul_in_path(path: str | os.PathLike | bytes) -> str | None:
    """Why ``path`` cannot name a file because it holds a NUL character (no file system allows one), or None."""
    text = os.fsdecode(path) if isinstance(path, (str, bytes, os.PathLike)) else ""
    k = text.find("\0")
    if k < 0:
        return None
    return (f"{text!r} holds a NUL character (\\x00) at position {k}, which no file name can: check how the path "
            "was built (a C string, a padded field, a pasted value)")


def why_missing(path: str | os.PathLike) -> str:
    """Why ``path`` cannot be opened although it was named: ``"does not exist"``, a dangling link or a link loop."""
    p = Path(path)
    if not p.is_symlink():
        parent = next((a for a in p.parents if a.is_symlink() and not a.exists()), None)
        if parent is not None:
            return f"does not exist: its folder {str(parent)!r} is a symbolic link {_link_problem(parent)}"
        return "does not exist"
    return f"is a symbolic link {_link_problem(p)}"


def _link_problem(p: Path) -> str:
    chain, seen = [str(p)], {os.path.abspath(p)}
    current = p
    for _ in range(40):
        target = Path(os.readlink(current))
        current = target if target.is_absolute() else current.parent / target
        key = os.path.abspath(current)
        chain.append(str(target))
        if key in seen:
            return f"in a loop ({' -> '.join(chain)}): it leads back to itself; point it at a real file"
        seen.add(key)
        if not current.is_symlink():
            break
    else:
        return f"chain longer than 40 links ({' -> '.join(chain[:4])} -> ...); point it at a real file"
    if not current.exists():
        return f"to {str(current)!r}, which does not exist (a dangling link); point it at a real file"
    return f"to {str(current)!r}"


def foreign_encoding(head: bytes) -> str | None:
    """What is wrong with a text file's encoding, from its first bytes (None: UTF-8 or ASCII, as footzoo reads).

    UTF-16 and UTF-32 (with a byte-order mark, or without one: every second or fourth byte NUL) are
    named with the conversion; a start of NUL bytes is named as damage.
    """
    head = head[:SNIFF_BYTES]
    for bom, name in FOREIGN_BOMS:
        if head.startswith(bom):
            return _convert(name) if _reads_as(head, name) else None
    if not head:
        return None
    sample = head[:512]
    if len(sample) >= 8:
        nuls = [sample[k::2].count(0) / len(sample[k::2]) for k in (0, 1)]
        if max(nuls) > 0.4 and min(nuls) < 0.05 and _reads_as(sample, "UTF-16"):
            return _convert("UTF-16")
    lead = len(head) - len(head.lstrip(b"\0"))
    if lead:
        return (f"starts with {lead}{'+' if lead == len(head) else ''} NUL byte(s) (0x00), not text: the file was "
                "damaged while it was written (a logger that pre-allocates its file, a power cut, a full card) or is "
                "not a text file; recover the data from the logger or re-export it")
    return None


def not_utf8(path: str | os.PathLike) -> str:
    """Where a text file stops being UTF-8: the byte, its offset and line, and the fix (the file read in blocks).

    A parser's own ``UnicodeDecodeError`` counts from the start of the block it was decoding, not of the file.
    """
    decoder = codecs.getincrementaldecoder("utf-8")()
    offset, line = 0, 1
    with open(path, "rb") as fh:
        while block := fh.read(1 << 20):
            try:
                decoder.decode(block)
            except UnicodeDecodeError as err:
                at = offset + err.start
                line += block.count(b"\n", 0, err.start)
                return (f"not UTF-8 text (byte 0x{block[err.start]:02x} at offset {at}, line {line}): another "
                        "encoding (Latin-1 or Windows-1252, e.g. a degree sign or a name with an accent); save the "
                        "file as UTF-8 (iconv -f latin1 -t utf-8 in.csv > out.csv)")
            offset += len(block)
            line += block.count(b"\n")
    return "not UTF-8 text; save the file as UTF-8 (iconv -f latin1 -t utf-8 in.csv > out.csv)"


def _reads_as(head: bytes, name: str) -> bool:
    """Whether ``head`` decodes as mostly printable text in ``name`` (UTF-16/32; either byte order)."""
    width = 4 if name == "UTF-32" else 2
    body = head[: len(head) // width * width]
    for codec in ((name.lower(),) if head[:2] in (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)
                  else (f"{name.lower()}-le", f"{name.lower()}-be")):
        try:
            text = body.decode(codec, errors="strict")
        except UnicodeDecodeError:
            continue
        if text and sum(c.isprintable() or c in "\r\n\t" for c in text) >= 0.9 * len(text):
            return True
    return False


def _convert(name: str) -> str:
    return (f"is {name} text; footzoo reads UTF-8: convert it (iconv -f {name} -t UTF-8 in.csv > out.csv), or "
            "save it again as 'CSV UTF-8'")


def nul_runs(data: bytes, limit: int = 3) -> list[tuple[int, int]]:
    """The first ``limit`` runs of NUL bytes in ``data``: ``(offset, length)`` each."""
    out, k = [], data.find(b"\0")
    while k >= 0 and len(out) < limit:
        end = k
        while end < len(data) and data[end] == 0:
            end += 1
        out.append((k, end - k))
        k = data.find(b"\0", end)
    return out


def nul_padding(data: bytes) -> int:
    """How many NUL bytes end ``data`` (padding a logger left after the last line)."""
    return len(data) - len(data.rstrip(b"\0"))


def damaged_text(name: str, data: bytes) -> str | None:
    """What is wrong with text ``data`` (the whole file) that NUL bytes reveal, with the line; None when nothing.

    NUL bytes at the very end (padding) are not a problem here: :func:`nul_padding` counts them.
    """
    body = data[:len(data) - nul_padding(data)]
    runs = nul_runs(body, 1)
    if not runs:
        return None
    offset, length = runs[0]
    line = body.count(b"\n", 0, offset) + 1
    if line == 1:  # in the header line: not a text table at all
        return (f"{name}: not a text file (a NUL byte 0x00 at byte {offset}, in its first line): binary data, or a "
                "file damaged from its start; give the recording's text (CSV) export, or the format that reads it")
    return (f"{name}: a run of {length} NUL bytes (0x00) at byte {offset} (line {line}): the file was damaged while "
            "it was written (a power cut, a full card, a logger's crash); the rows there are not data. Cut the damaged "
            f"part out (the rows around line {line}) or recover the file, then read it again")


def sha256(path: str | os.PathLike) -> str:
    """SHA-256 (hex) of a file's bytes, read in blocks of 1 MiB."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
