"""Validates every SSP document of a .ssp archive against the Modelica Association's schemas.

    validate_schema.py SCHEMA_DIR SYSTEM.ssp

SCHEMA_DIR holds the schema folders 1.0/ and 2.0/ (tests/ssp/schema): SystemStructure.ssd is
checked against SystemStructureDescription.xsd, each .ssv against
SystemStructureParameterValues.xsd and each .ssm against SystemStructureParameterMapping.xsd, of
the version the document declares, and also of 2.0 when it declares 1.0 (SSP 2.0 reads 1.0
files). One line per document and schema; exit status 1 if any is invalid.
"""

import sys
import zipfile

from lxml import etree

SCHEMAS = {".ssd": "SystemStructureDescription.xsd",
           ".ssv": "SystemStructureParameterValues.xsd",
           ".ssm": "SystemStructureParameterMapping.xsd"}


def main():
    schema_dir, ssp = sys.argv[1], sys.argv[2]
    failed = 0
    checked = 0
    with zipfile.ZipFile(ssp) as z:
        for name in z.namelist():
            ext = name[name.rfind("."):].lower()
            if ext not in SCHEMAS:
                continue
            doc = etree.fromstring(z.read(name))
            version = doc.get("version", "")
            versions = ["1.0", "2.0"] if version.startswith("1.") else ["2.0"]
            for v in versions:
                schema = etree.XMLSchema(file=f"{schema_dir}/{v}/{SCHEMAS[ext]}")
                checked += 1
                if schema.validate(doc):
                    print(f"{name}: valid against SSP {v}")
                else:
                    failed += 1
                    for e in schema.error_log:
                        print(f"{name}: SSP {v}: line {e.line}: {e.message}")
    if checked == 0:
        print(f"{ssp}: no SSP documents found")
        sys.exit(1)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
