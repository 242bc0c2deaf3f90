

def test_a_crafted_model_name_cannot_add_code_to_the_control_module():
    """The model's file name went into the module's docstring as it was: '\"\"\"' and a line break
    ended the docstring and the next line ran on import."""
    import ast

    from hwpts.io.export import _docstring_text

    name = 'x"""\nimport os;os.system("touch PWNED")\n""".json'
    text = f'"""model {_docstring_text(name)}."""\n'
    tree = ast.parse(text)
    assert len(tree.body) == 1 and isinstance(tree.body[0], ast.Expr)
    assert ast.literal_eval(text.strip()) == f"model {name}."
