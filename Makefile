# LiDAR Photogrammetry Toolkit - developer entry points (Debian 12; see scripts/test.sh).
SHELL := /bin/bash
.DEFAULT_GOAL := test
.PHONY: test demo package lint format model clean i18n

## test: install what is missing (apt QGIS, .venv, .venv-qgis), ruff, core + QGIS test suites
test:
	bash scripts/test.sh

## demo: core environment only, then the demo script
demo:
	bash scripts/test.sh --core-env
	.venv/bin/python scripts/demo.py

## package: lidarphoto.zip, installable with QGIS "Install from ZIP"
package:
	bash scripts/package.sh lidarphoto.zip

## i18n: add the code's new strings to i18n/*.ts (then translate them), build the .qm files
i18n:
	$(if $(wildcard .venv/bin/python),.venv/bin/python,python3) scripts/i18n.py

lint:
	bash scripts/test.sh --core-env
	.venv/bin/ruff check .
	.venv/bin/ruff format --check core plugin processing_provider tests/qgis __init__.py

format:
	bash scripts/test.sh --core-env
	.venv/bin/ruff format core plugin processing_provider tests/qgis __init__.py

## model: regenerate tests/qgis/data/trajectory_model.model3 (needs .venv-qgis from `make test`)
model:
	QT_QPA_PLATFORM=offscreen PROJ_DATA=/usr/share/proj .venv-qgis/bin/python tests/qgis/make_model.py

clean:
	rm -rf .venv .venv-qgis .qgis-settings .ci-logs lidarphoto.zip lidarphoto.egg-info
