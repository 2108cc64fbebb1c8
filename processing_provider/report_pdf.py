"""Every HTML report also as PDF, printed by QtWebKit (the engine QGIS's own HTML frames use).

The HTML reports are self-contained (inline CSS and SVG), so WebKit lays them out as a browser
would, and QPrinter writes them to an A4 PDF beside the HTML (``report.html`` ->
``report.pdf``). Printing needs a GUI application and its main thread: QGIS desktop,
``qgis_process`` (it runs on Qt's offscreen platform) or a QgsApplication created with the GUI;
where there is none, or no QtWebKit, the PDF is skipped with a message and the HTML stays.
"""

from __future__ import annotations

import os
from pathlib import Path

from qgis.PyQt.QtCore import QEventLoop, QThread, QTimer, QUrl
from qgis.PyQt.QtWidgets import QApplication

__all__ = ["pdf_path_of", "write_pdf"]

#: How long WebKit may take to lay out one report (ms); inline content loads at once.
LOAD_TIMEOUT_MS = 30_000


def pdf_path_of(html: str) -> str:
    """The PDF beside an HTML report: the same name with ``.pdf``."""
    return str(Path(html).with_suffix(".pdf"))


def can_print() -> str:
    """Why a PDF cannot be printed here ("" when it can)."""
    app = QApplication.instance()
    if not isinstance(app, QApplication) or app.thread() is not QThread.currentThread():
        return "no GUI application in this thread"
    try:
        from qgis.PyQt.QtPrintSupport import QPrinter  # noqa: F401
        from qgis.PyQt.QtWebKitWidgets import QWebPage  # noqa: F401
    except ImportError as exc:
        return f"QtWebKit is not available ({exc})"
    return ""


def write_pdf(html: str, pdf: str | None = None) -> str:
    """Print the HTML report ``html`` to ``pdf`` (default: :func:`pdf_path_of`); returns the
    PDF's path. Written to a temporary file beside it and renamed, so a failed print leaves no
    half-written PDF. Raises RuntimeError naming the file when it cannot print."""
    from qgis.PyQt.QtGui import QPageSize
    from qgis.PyQt.QtPrintSupport import QPrinter
    from qgis.PyQt.QtWebKitWidgets import QWebPage

    why = can_print()
    if why:
        raise RuntimeError(f"{html}: no PDF: {why}")
    pdf = pdf or pdf_path_of(html)
    text = Path(html).read_text(encoding="utf-8")
    page = QWebPage()
    loop = QEventLoop()
    done: list[bool] = []
    page.mainFrame().loadFinished.connect(lambda ok: (done.append(ok), loop.quit()))
    QTimer.singleShot(LOAD_TIMEOUT_MS, loop.quit)
    page.mainFrame().setHtml(text, QUrl.fromLocalFile(str(Path(html).resolve())))
    if not done:
        loop.exec()
    if not done or not done[0]:
        raise RuntimeError(f"{html}: no PDF: the page did not load")
    printer = QPrinter(QPrinter.PrinterMode.HighResolution)
    printer.setOutputFormat(QPrinter.OutputFormat.PdfFormat)
    printer.setPageSize(QPageSize(QPageSize.PageSizeId.A4))
    part = f"{pdf}.{os.getpid()}.part"
    printer.setOutputFileName(part)
    try:
        page.mainFrame().print(printer)
        del printer  # closes the file
        if not Path(part).is_file() or Path(part).stat().st_size == 0:
            raise RuntimeError(f"{html}: no PDF: the printer wrote nothing")
        os.replace(part, pdf)
    finally:
        if os.path.exists(part):
            os.remove(part)
    return pdf
