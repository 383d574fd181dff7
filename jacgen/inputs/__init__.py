"""The robot file and URDF input: the Robot type, the YAML reader and its value grammar, the
URDF chain reader and its conversion to a DH table, and the names every generated language
accepts (with the languages' reserved words)."""
