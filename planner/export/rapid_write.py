"""The RAPID routine that writes the measurements file for ``wobjcal calibrate``."""

from __future__ import annotations

MEASURED_FILE = "wobjcal_measured.json"


def _write_points(cond: str, left: str, right: str) -> list[str]:
    """Write ``"id": [x, y, z]`` (mm) of the entries where ``cond`` holds, comma-separated."""
    q = '""'
    return [
        '        sep:="";',
        "        FOR i FROM 1 TO nPoints DO",
        f"            IF {cond} THEN",
        f'                Write file,sep+"{q}"+measuredId{{i}}+"{q}: {left}"\\NoNewLine;',
        '                Write file,NumToStr(measured{i}.x,4)+", "\\NoNewLine;',
        '                Write file,NumToStr(measured{i}.y,4)+", "\\NoNewLine;',
        f'                Write file,NumToStr(measured{{i}}.z,4)+"{right}"\\NoNewLine;',
        '                sep:=", ";',
        "            ENDIF",
        "        ENDFOR",
    ]


def write_proc(plan_digest: str = "") -> list[str]:
    """``WriteMeasurements``: the measurements file, with the plan's digest (``""``: none)."""
    q = '""'
    return [
        "    ! Write the measurements as wobjcal.measurements/1 for `wobjcal calibrate`",
        "    PROC WriteMeasurements()",
        "        VAR iodev file;",
        '        VAR string sep:="";',
        f'        Open "HOME:"\\File:="{MEASURED_FILE}",file\\Write;',
        f'        Write file,"{{{q}schema{q}: {q}wobjcal.measurements/1{q}, '
        f'{q}frame{q}: {q}base{q}, {q}units{q}: {q}mm{q},";',
        f'        Write file," {q}points{q}: {{"\\NoNewLine;',
        *_write_points("measuredOk{i} AND NOT measuredRetake{i}", "[", "]"),
        f'        Write file,"}}, {q}retakes{q}: {{"\\NoNewLine;',
        *_write_points("measuredOk{i} AND measuredRetake{i}", "[[", "]]"),
        f'        Write file,"}}, {q}failed{q}: {{"\\NoNewLine;',
        '        sep:="";',
        "        FOR i FROM 1 TO nPoints DO",
        '            IF NOT measuredOk{i} AND NOT measuredRetake{i} AND measuredErr{i}<>"" THEN',
        f'                Write file,sep+"{q}"+measuredId{{i}}+"{q}: {q}"\\NoNewLine;',
        f'                Write file,measuredErr{{i}}+"{q}"\\NoNewLine;',
        '                sep:=", ";',
        "            ENDIF",
        "        ENDFOR",
        f'        Write file,"}}, {q}plan_digest{q}: {q}{plan_digest}{q}}}";',
        "        Close file;",
        f'        TPWrite "wobjcal: measurements written to HOME:/{MEASURED_FILE}";',
        "    ENDPROC",
    ]
