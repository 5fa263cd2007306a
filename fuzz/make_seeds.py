#!/usr/bin/env python3
"""Regenerates the seed corpora fuzz/corpus/<target>/ and the dictionaries fuzz/dict/<target>.dict;
the committed files are what the fuzzers and CI use (python3 fuzz/make_seeds.py [records folder]).

Seeds are real inputs kept small, so that libFuzzer's default input length stays a few KB and
each execution is fast:
- input_toml: every model in examples/ and examples/paper/, with ensemble folders pointed at the
  fuzzer's own records/ folder, plus record excitations of each format;
- input_set: the same models, each with --set overrides after NUL bytes;
- record_at2, record_cosmos: the shipped records trimmed to their header and a few dozen lines of
  values, NPTS changed to the values kept (so that the seeds are valid records);
- record_columns: the El Centro column file trimmed likewise, and variants (one column, a third
  column, other separators, options lines).
The records come from data/ground_motions/ (or ../shared/data/ground_motions/ until they are in
the repository), or from the folder given as the argument.
"""

import pathlib
import re
import shutil
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
CORPUS = ROOT / "fuzz" / "corpus"
RECORDS = ROOT / "data" / "ground_motions"
if len(sys.argv) > 1:
    RECORDS = pathlib.Path(sys.argv[1])
elif not RECORDS.is_dir():
    RECORDS = ROOT.parent / "shared" / "data" / "ground_motions"
KEEP_LINES = 30  # lines of values kept from each record


def write(target, name, data):
    path = CORPUS / target / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data.encode() if isinstance(data, str) else data)


def lines_of(path):
    return path.read_text(encoding="latin-1").splitlines()


def count_values(lines):
    return sum(len(line.split()) for line in lines)


def models():
    for path in sorted((ROOT / "examples").glob("*.toml")) + sorted((ROOT / "examples" / "paper").glob("*.toml")):
        text = path.read_text()
        # Ensembles: the fuzzers' scratch folder has the records in records/.
        text = re.sub(r'(?m)^folder = ".*"', 'folder = "records"', text)
        name = path.stem if path.parent.name == "examples" else "paper_" + path.stem
        yield name, text


RECORD_EXCITATIONS = {
    "record_at2": '[excitation]\nkind = "record"\nfile = "records/RSN6_IMPVALL.I_I-ELC180.AT2"\ntarget_pga_g = 0.3\n',
    "record_cosmos": '[excitation]\nkind = "record"\nfile = "records/AKBMR.BNZ.acc.V2c"\nformat = "cosmos"\nunits = "cm/s2"\n',
    "record_columns": '[excitation]\nkind = "record"\nfile = "records/elcentro_1940_elc180_g.txt"\nformat = "columns"\nunits = "g"\nscale = 2.0\n',
}

OVERRIDES = {
    "fig2c_ratio0.8": ["model.dimensionless.eta=0", "model.dimensionless.mu=0", "model.dimensionless.epsilon=0",
                       "model.dimensionless.restitution=1", "excitation.ratio=1.0"],
    "three_buildings_el_centro": ["frames[2].mass=4.5e5", "gap_elements.gap=0.05", "excitation.target_pga_g=0.3",
                                  "analysis.integrator=exact"],
    "free_vibration_impact": ["analysis.duration=2", "analysis.separation=force", "title=override"],
    "study_eta_mu": ["frf.points=5", "study.threads=1"],
    "optimize_gap_elements": ["optimize.global_evaluations=10", "analysis.integrator=exact"],
    "ensemble_fig2_frames": ["ensemble.pattern=*.txt", "ensemble.baseline=true"],
    "paper_fig2a": ["frf.sweep=both", "model.storeys=[2, 3]", "frf.points=5"],
}


def main():
    shutil.rmtree(CORPUS, ignore_errors=True)

    fig2c = None
    for name, text in models():
        write("input_toml", name + ".toml", text)
        if name in OVERRIDES:
            write("input_set", name, "\0".join([text] + OVERRIDES[name]))
        if name == "fig2c_ratio0.8":
            fig2c = text
    for name, excitation in RECORD_EXCITATIONS.items():
        text = re.sub(r'(?ms)^\[excitation\]\n.*?(?=^\[)', excitation + "\n", fig2c)
        text = text.replace("duration = 20.0\n", "")
        write("input_toml", name + ".toml", text)
        scale = "excitation.target_pga_g=0.5" if "target_pga_g" in text else "excitation.scale=0.5"
        write("input_set", name, "\0".join([text, scale, "analysis.dt=0.005"]))

    # AT2: header (4 lines) and KEEP_LINES lines of values, NPTS set to the values kept.
    for path in sorted(RECORDS.glob("*.AT2")):
        lines = lines_of(path)
        body = lines[4:4 + KEEP_LINES]
        npts = count_values(body)
        header = re.sub(r"NPTS=\s*\d+", "NPTS= %6d" % npts, lines[3])
        write("record_at2", path.name, "\n".join(lines[:3] + [header] + body) + "\n")
    # A record in the unlabelled and reversed header spellings of FORMATS.md.
    at2 = lines_of(RECORDS / "RSN6_IMPVALL.I_I-ELC180.AT2")
    body = at2[4:4 + 8]
    write("record_at2", "unlabelled.AT2", "\n".join(at2[:3] + ["%d    .0100" % count_values(body)] + body) + "\n")
    write("record_at2", "reversed_crlf.AT2",
          "\r\n".join(at2[:3] + [".0100   %d   DT, NPTS" % count_values(body)] + body) + "\r\n")

    # COSMOS V2: every header, KEEP_LINES values, the count line changed, End-of-data kept.
    for path in sorted(RECORDS.glob("*.V2*")):
        lines = lines_of(path)
        data = next(i for i, line in enumerate(lines) if "acceleration pts" in line)
        count_line = re.sub(r"^\s*\d+", "%8d" % KEEP_LINES, lines[data])
        end = [line for line in lines[data + 1:] if line.startswith("End-of-data")][:1]
        values = lines[data + 1:data + 1 + KEEP_LINES]
        write("record_cosmos", path.name, "\n".join(lines[:data] + [count_line] + values + end) + "\n")
        # Five values a line (Format=(5E15.6)), and a second channel block after the first.
        five = ["".join("%15s" % v.strip() for v in values[i:i + 5]) for i in range(0, len(values), 5)]
        block = lines[:data] + [count_line.replace("1E15.6", "5E15.6")] + five + end
        write("record_cosmos", "two_channels_five_a_line.V2c", "\n".join(block + block) + "\n")

    # Column files.
    columns = lines_of(ROOT / "examples" / "records" / "elcentro_1940_elc180_g.txt")
    first = next(i for i, line in enumerate(columns) if not line.startswith("#"))
    head, rows = columns[:first], columns[first:first + KEEP_LINES]
    write("record_columns", "elcentro_columns.txt", "\n".join(head + rows) + "\n")
    write("record_columns", "three_columns.txt",
          "# fuzz: column=3 units=m/s2\ntime,velocity,acceleration\n" +
          "\n".join("%s, 0.0, %s" % tuple(r.split()) for r in rows) + "\n")
    write("record_columns", "semicolons_cm_crlf.txt",
          "# fuzz: units=cm/s2 target_pga_g=0.25\r\n% time; a\r\n" +
          "\r\n".join("%s;\t%s" % tuple(r.split()) for r in rows) + "\r\n")
    write("record_columns", "single.txt",
          "# fuzz: single dt=0.01 units=g scale=1.5\nacceleration (g)\n" +
          "\n".join(r.split()[1] for r in rows) + "\n")
    write("record_columns", "no_units.txt", "# fuzz: units=none\n" + "\n".join(rows[:5]) + "\n")

    dictionaries()


def dictionary(target, words):
    """libFuzzer's dictionary format: one quoted entry a line, \\\\, \\" and \\xNN escaped."""
    def quote(word):
        out = "".join("\\\\" if c == "\\" else '\\"' if c == '"' else c if " " <= c <= "~" else "\\x%02x" % ord(c)
                      for c in word)
        return '"%s"\n' % out
    path = ROOT / "fuzz" / "dict" / (target + ".dict")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("# Generated by fuzz/make_seeds.py.\n" + "".join(quote(w) for w in sorted(set(words))))


NUMBERS = ["0", "1", "-1", "2", ".0100", "1E-03", "E+00", "D+00", "-999", "-999.000000", "1E300", "INF", "NAN",
           "4294967297", "99999999999999999999999", " ", "\t", "\n", "\r\n", "-", "+", "."]


def dictionaries():
    # Every key and quoted value of the input documentation, plus TOML syntax and awkward numbers.
    docs = "".join((ROOT / "docs" / name).read_text() for name in ("input.md", "studies.md", "records.md"))
    keys = set(re.findall(r"`([a-z][a-z_0-9]*(?:\.[a-z_0-9]+)*)`", docs))
    values = set(re.findall(r'"([a-z_0-9*./]+)"', docs))
    toml = sorted(keys) + ['"%s"' % v for v in sorted(values)] + [
        "[model]", "[model.dimensionless]", "[[frames]]", "[gap_elements]", "[[gap_elements.override]]",
        "[initial]", "[excitation]", "[analysis]", "[frf]", "[study]", "[[study.parameter]]", "[optimize]",
        "[[optimize.variable]]", "[ensemble]", " = ", "[", "]", "{", "}", ",", '"', "'", "'''", '"""', "#", "\n",
        "true", "false", "inf", "-inf", "nan", "0x", "0o", "0b", "1e308", "1e-300", "9223372036854775807",
        "4294967297", "2147483648", "-1", "0.0", "1979-05-27T07:32:00Z", "records/", ".AT2", ".V2c", ".txt"]
    dictionary("input_toml", toml)
    dictionary("input_set", toml + ["\0", "=", ".", "[1]", "[2]", "frames[2].", "model.dimensionless.",
                                     "excitation.", "analysis.", "frf.", "study.", "optimize.", "ensemble."])
    dictionary("record_at2", NUMBERS + [
        "PEER NGA STRONG MOTION DATABASE RECORD", "ACCELERATION TIME SERIES IN UNITS OF G", "UNITS OF G", "(G)",
        "IN G", "CM/S/S", "CM/SEC/SEC", "CM/S2", "CM/S^2", "CM/S**2", "M/S/S", "M/S2", "M/SEC2", "VELOCITY",
        "DISPLACEMENT", "NPTS=", "NPTS", "DT=", "DT", "SEC", "SEC,", "NPTS, DT", "DT, NPTS", ",", "=", "POLE @"])
    dictionary("record_cosmos", NUMBERS + [
        "Corrected acceleration", "Uncorrected acceleration", "Raw acceleration counts",
        "(Format v01.20 with 13 text lines)", "with", "text lines",
        "Integer-header values follow on", "Real-header values follow on", "lines, Format= (10I8)",
        "lines, Format= (5F15.6)", 'Comment line(s) follow, each starting with a "|":', "Comment line", "|",
        "acceleration pts, approx", "secs, units=", "units=", "cm/sec2", "cm/sec2(04)", "g", "m/s2", "gal",
        ",Format=(1E15.6)", "End-of-data", "End-of-data for ChanBNZ acceleration",
        "Values used when parameter or data value is unknown/unspecified:"])
    dictionary("record_columns", NUMBERS + [
        "# fuzz:", "# fuzz: single dt=0.01", " single", " dt=", " column=", " column=3", " units=", " units=g",
        " units=m/s2", " units=cm/s2", " units=none", " scale=", " target_pga_g=", "#", "%", ",", ";", "time",
        "acceleration"])


if __name__ == "__main__":
    main()
