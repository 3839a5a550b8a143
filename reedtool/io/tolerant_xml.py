"""Parse model XML the way Gazebo's loaders do: what TinyXML2 reads, reedtool reads.

Every XML format reedtool reads for Gazebo goes through here: SDF (libsdformat parses it
with TinyXML2), URDF (Gazebo converts it through sdformat's URDF parser, TinyXML2 again),
COLLADA meshes and launch files. TinyXML2 is not a validating XML parser. Gazebo
therefore loads files that libxml2 (lxml, xmllint) refuses; two kinds occur in files
people fly today:

* `--` inside a comment (gz-sim's own `examples/worlds/quadcopter.sdf`), which XML 1.0
  forbids;
* a namespace prefix used without its `xmlns:` declaration (PX4's optical-flow sensor
  writes `gz:` attributes), which the Namespaces in XML spec forbids.

Three more occur in meshes and generated files: a `<` inside an attribute value (an STL
converter's `<node id="<STL_BINARY>">`), a `&` that starts no entity (`name="Motor&Prop"`),
and an XML declaration after a comment or blank lines (a generated file's header).

The strict parse is tried first. Only when it fails are these patterns cleaned in a copy
of the text that keeps every line number (a `-` becomes a space, a misplaced declaration
blanks, `<` and a bare `&` are escaped; the missing namespace declarations go inside the
root start tag, on its own line), and the copy is parsed. Anything else that is malformed stays a one-line error, as it is in
Gazebo. The caller turns the returned notes into one information finding per file.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from reedtool.errors import ReedtoolError

# URN the undeclared prefixes are bound to; never written to a user file.
UNDECLARED_NS = "urn:reedtool:undeclared:"

_COMMENT = re.compile(r"<!--(.*?)-->", re.DOTALL)
_START_TAG = re.compile(r"<([A-Za-z_][^<>]*)>")
_PREFIXED_TAG = re.compile(r"^([A-Za-z_][\w.-]*):[A-Za-z_]")
_PREFIXED_ATTR = re.compile(r"\s([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*\s*=")
_QUOTED = re.compile(r"\"[^\"]*\"|'[^']*'")
_DECLARED = re.compile(r"xmlns:([A-Za-z_][\w.-]*)\s*=")
_ROOT_START = re.compile(r"<(?![?!])[A-Za-z_][\w.:-]*")
_RESERVED = {"xml", "xmlns"}


@dataclass(frozen=True)
class Tolerated:
    """A construct TinyXML2 accepts and strict XML tools refuse."""

    line: int
    what: str          # what the construct is, for the message


def _parser(remove_comments: bool = False) -> etree.XMLParser:
    return etree.XMLParser(remove_blank_text=False, resolve_entities=False, huge_tree=True,
                           encoding="utf-8", no_network=True, remove_comments=remove_comments)


def _line_of(text: str, offset: int) -> int:
    return text.count("\n", 0, offset) + 1


def _clean_comments(text: str) -> tuple[str, list[Tolerated]]:
    found: list[Tolerated] = []

    def fix(match: re.Match) -> str:
        body = match.group(1)
        if "--" not in body and not body.endswith("-"):
            return match.group(0)
        found.append(Tolerated(_line_of(text, match.start()), "'--' inside a comment"))
        body = re.sub(r"-(?=-)", " ", body)
        if body.endswith("-"):
            body = body[:-1] + " "
        return f"<!--{body}-->"

    return _COMMENT.sub(fix, text), found


DECLARATION_AFTER_BLANKS = "XML declaration not at the start (after blank lines)"
DECLARATION_AFTER_CONTENT = "XML declaration after a comment (TinyXML2, so gz-sim, refuses it)"
_XML_DECL = re.compile(r"<\?xml\s[^>]*\?>")
_ENTITY = re.compile(r"&(#\d+|#x[0-9A-Fa-f]+|[A-Za-z_][\w.-]*);")


def _clean_declaration(text: str) -> tuple[str, list[Tolerated]]:
    """An XML declaration after blank lines or a comment (a generated file's header line):
    TinyXML2 reads it as an ordinary node; blanked here, newlines kept."""
    match = _XML_DECL.search(text)
    if match is None or match.start() == 0:
        return text, []
    blank = re.sub(r"[^\n]", " ", match.group(0))
    # Blank lines before it: TinyXML and TinyXML2 alike read it. A comment before it:
    # TinyXML (Gazebo classic's sdformat 9) reads it, TinyXML2 5+ (sdformat 10+, gz-sim)
    # refuses it ('wellLocated').
    what = (DECLARATION_AFTER_BLANKS if not text[:match.start()].strip()
            else DECLARATION_AFTER_CONTENT)
    return (text[:match.start()] + blank + text[match.end():],
            [Tolerated(_line_of(text, match.start()), what)])


def _escape_markup(text: str) -> tuple[str, list[Tolerated]]:
    """A '<' inside an attribute value and a '&' that starts no entity, which TinyXML2 (and
    the COLLADA loaders of gz-common and Gazebo classic) read as plain characters, escaped.
    Comments, CDATA, processing instructions and DOCTYPE are copied as they are; no
    newline is added or removed, so line numbers stay."""
    out: list[str] = []
    found: dict[str, int] = {}
    i, n = 0, len(text)

    def note(what: str, at: int) -> None:
        found.setdefault(what, _line_of(text, at))

    def amp(at: int) -> str:
        if _ENTITY.match(text, at):
            return "&"
        note("'&' that starts no entity", at)
        return "&amp;"

    while i < n:
        ch = text[i]
        if ch == "<":
            for opener, closer in (("<!--", "-->"), ("<![CDATA[", "]]>"), ("<?", "?>"),
                                   ("<!", ">")):
                if text.startswith(opener, i):
                    end = text.find(closer, i + len(opener))
                    end = n if end < 0 else end + len(closer)
                    out.append(text[i:end])
                    i = end
                    break
            else:
                # a tag: copy to its closing '>' outside quotes, escaping inside quotes
                out.append("<")
                i += 1
                quote = None
                while i < n:
                    c = text[i]
                    if quote:
                        if c == quote:
                            quote = None
                            out.append(c)
                        elif c == "<":
                            note("'<' inside an attribute value", i)
                            out.append("&lt;")
                        elif c == "&":
                            out.append(amp(i))
                        else:
                            out.append(c)
                    elif c in "\"'":
                        quote = c
                        out.append(c)
                    elif c == ">":
                        out.append(c)
                        i += 1
                        break
                    else:
                        out.append(c)
                    i += 1
            continue
        out.append(amp(i) if ch == "&" else ch)
        i += 1
    return "".join(out), [Tolerated(line, what) for what, line in found.items()]


def _undeclared_prefixes(text: str) -> dict[str, int]:
    """Prefix -> first line it is used on, for prefixes no xmlns: declares."""
    no_comments = _COMMENT.sub(lambda m: " " * len(m.group(0)), text)
    declared = set(_DECLARED.findall(no_comments)) | _RESERVED
    used: dict[str, int] = {}
    # Only element and attribute names count: text and attribute values may hold "a:b".
    for tag in _START_TAG.finditer(no_comments):
        inside = _QUOTED.sub(lambda m: " " * len(m.group(0)), tag.group(1))
        for pattern in (_PREFIXED_TAG, _PREFIXED_ATTR):
            for match in pattern.finditer(inside):
                prefix = match.group(1)
                if prefix not in declared:
                    line = _line_of(no_comments, tag.start(1) + match.start(1))
                    used[prefix] = min(line, used.get(prefix, line))
    return used


def _declare(text: str, prefixes: dict[str, int]) -> str:
    no_comments = _COMMENT.sub(lambda m: " " * len(m.group(0)), text)
    root = _ROOT_START.search(no_comments)
    if root is None or not prefixes:
        return text
    declarations = "".join(f' xmlns:{p}="{UNDECLARED_NS}{p}"' for p in sorted(prefixes))
    return text[:root.end()] + declarations + text[root.end():]


def parse_tolerant(text: str, file: Path | str, *, remove_comments: bool = False,
                   error: str = "malformed XML", line_known: bool = True,
                   hint: str = "fix the XML syntax at that position",
                   ) -> tuple[etree._Element, list[Tolerated]]:
    """(root element, what was tolerated) of XML text, or a one-line ReedtoolError.

    `error` starts the error message ("not a COLLADA file", "not a launch file");
    `line_known` False when the text's lines are not the file's (an expansion's output).
    """
    data = text.encode("utf-8")
    parser = _parser(remove_comments)
    try:
        return etree.fromstring(data, parser), []
    except etree.XMLSyntaxError as strict_error:
        cleaned, tolerated = _clean_comments(text)
        cleaned, misplaced = _clean_declaration(cleaned)
        cleaned, escaped = _escape_markup(cleaned)
        tolerated += misplaced + escaped
        prefixes = _undeclared_prefixes(cleaned)
        tolerated += [Tolerated(line, f"namespace prefix '{p}:' used without an xmlns:{p} "
                                      "declaration") for p, line in sorted(prefixes.items())]
        if not tolerated:
            raise ReedtoolError(f"{error}: {strict_error.msg}", file=file,
                                line=strict_error.lineno if line_known else None,
                                hint=hint) from None
        try:
            root = etree.fromstring(_declare(cleaned, prefixes).encode("utf-8"),
                                    _parser(remove_comments))
        except etree.XMLSyntaxError as exc:
            raise ReedtoolError(f"{error}: {exc.msg}", file=file,
                                line=exc.lineno if line_known else None, hint=hint) from None
        return root, sorted(tolerated, key=lambda t: t.line)


def late_declaration_issues(items: list[Tolerated], file: Path | str) -> list:
    """A parse issue ("xml-declaration-late") where a comment precedes the XML declaration:
    Gazebo classic reads that file, gz-sim (TinyXML2 5+) refuses it (S124)."""
    from reedtool.model import ParseIssue, SourceLoc

    return [ParseIssue("xml-declaration-late", f"the XML declaration on line {t.line} follows "
                       "a comment: TinyXML2 (libsdformat 10+, so gz-sim) refuses the file; "
                       "Gazebo classic's TinyXML reads it", SourceLoc(str(file), t.line),
                       Path(file).name)
            for t in items if t.what == DECLARATION_AFTER_CONTENT]


def tolerated_message(items: list[Tolerated]) -> str:
    """The one information message per file (S119) for what was tolerated in it."""
    what = "; ".join(f"line {t.line}: {t.what}" for t in sorted(set(items), key=lambda t: t.line))
    return (f"Gazebo (TinyXML2) reads this file, but strict XML tools (xmllint, lxml, XML "
            f"editors) reject it: {what}")


def local_tag(el: etree._Element) -> str:
    """The tag without a namespace that only reedtool's tolerant parse attached."""
    tag = el.tag
    if isinstance(tag, str) and tag.startswith("{" + UNDECLARED_NS):
        prefix, _, name = tag[len(UNDECLARED_NS) + 1:].partition("}")
        return f"{prefix}:{name}"
    return tag
