"""Every stage reads its input tables through one function that refuses bad files clearly."""

from __future__ import annotations

import pytest

from pipeline.errors import UserInputError
from pipeline.fileio import read_table, read_user_csv


def test_reads_a_good_table(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("material,psi_deg\nDS20,10\n")
    assert read_table(p, "a table", required=["material"])["psi_deg"].tolist() == [10]


@pytest.mark.parametrize(
    "content, message",
    [
        (None, "file not found; pass an angles.csv"),
        ("", "not a readable CSV"),
        ("a,b\n1,2\n", "missing column(s) ['material']"),
    ],
)
def test_bad_tables_name_the_file_and_the_fix(tmp_path, content, message):
    p = tmp_path / "angles.csv"
    if content is not None:
        p.write_text(content)
    with pytest.raises(UserInputError) as exc:
        read_table(p, "an angles.csv written by 'measure'", required=["material"])
    assert str(p) in str(exc.value) and message in str(exc.value)


def test_grasp_log_and_force_tables_use_it(tmp_path):
    from pipeline.force.aggregate_force import read_tables
    from pipeline.force.grasp import read_grasp_log

    with pytest.raises(UserInputError, match="file not found"):
        read_grasp_log(tmp_path / "nope.csv")
    (tmp_path / "e.csv").write_text("image,psi\nx,1\n")
    with pytest.raises(UserInputError, match="force_n"):
        read_tables([tmp_path / "e.csv"])


def test_a_spreadsheets_csv_keeps_quoted_fields_and_text_with_commas_whole(tmp_path):
    # only a cell that is one number with a decimal comma gets a decimal point: a quoted field
    # holding the separator, a list, a name with a comma and an empty cell stay as written
    p = tmp_path / "grasp.csv"
    p.write_text(
        'object;mass_g;note;roi\n"cup; blue";12,5;"held 3,5 s";[1, 2, 30, 40]\negg;-0,5;;\n'
    )
    df = read_user_csv(p, dtype=str, keep_default_na=False)
    assert df.to_dict("records") == [
        {"object": "cup; blue", "mass_g": "12.5", "note": "held 3,5 s", "roi": "[1, 2, 30, 40]"},
        {"object": "egg", "mass_g": "-0.5", "note": "", "roi": ""},
    ]
    # a comma-separated file is read as pandas reads it (its quoted decimal commas stay text)
    p.write_text('a,b\n"1,5",2.5\n')
    assert read_user_csv(p).to_dict("records") == [{"a": "1,5", "b": 2.5}]
