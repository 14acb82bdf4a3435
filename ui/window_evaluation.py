"""How the main window evaluates: document edits schedule a debounced
evaluation on the `EvalWorker`; its progress and report are drawn here."""

from __future__ import annotations

from engine.graph import EvalReport, NodeResult


class WindowEvaluation:
    """Mixin of `MainWindow`: auto-evaluation, cancel, progress bar and the
    report's log lines (``self`` is the QMainWindow)."""

    # -- document events -> evaluation ---------------------------------------------------
    def _on_doc_event(self, event: str, payload) -> None:
        if event in ("node_moved", "label_changed", "annotation_changed"):
            return  # layout only: results cannot change
        if event == "node_removed" and payload == self.shown_stiffness_id:
            self.update_viewport()  # its material sphere goes now, not after the next evaluation
        if self.act_auto.isChecked():
            self._debounce.start()

    def _on_auto_toggled(self, on: bool) -> None:
        if on:
            self._debounce.start()

    def evaluate_now(self) -> None:
        """Evaluate the current document on the worker thread (never here)."""
        self._debounce.stop()
        if self._shutting_down:
            return
        try:
            snapshot = self.doc.snapshot()
        except Exception as exc:
            self.log("error", f"cannot evaluate: {exc}")
            return
        self._eval_total = len(snapshot.nodes)
        self.worker.request(snapshot, tag=self._generation)

    def adopt_result(self, node_id: str, outputs: dict, inputs: dict | None = None) -> bool:
        """Offer ``outputs`` as node ``node_id``'s result for the document as it is now (the RD
        dock's finished live growth); the next evaluation serves it cached if the evaluator
        accepts it (`EvalWorker.adopt`).  False when the document cannot be snapshotted."""
        try:
            snapshot = self.doc.snapshot()
        except Exception:
            return False
        self.worker.adopt(snapshot, node_id, outputs, inputs)
        return True

    def cancel_evaluation(self) -> None:
        self._debounce.stop()
        if self.worker.is_busy:
            self.log("info", "cancelling evaluation…")
        self.worker.cancel()

    @property
    def evaluation_idle(self) -> bool:
        """No evaluation running, queued or waiting for the debounce timer."""
        return not self.worker.is_busy and not self._debounce.isActive()

    def _on_eval_started(self, _number: int) -> None:
        self._eval_done = []
        self.cancel_button.setEnabled(True)
        self.progress.setValue(0)
        self.progress.setFormat("evaluating…")

    def _on_eval_progress(self, node_id: str, fraction: float) -> None:
        total = max(self._eval_total, 1)
        done = len(self._eval_done)
        self.progress.setValue(int(1000 * min(1.0, (done + fraction) / total)))
        self.progress.setFormat(f"{node_id}: {int(100 * fraction)}%   ({done}/{total} nodes)")

    def _on_eval_node_done(self, result: NodeResult) -> None:
        self._eval_done.append(result)
        total = max(self._eval_total, 1)
        self.progress.setValue(int(1000 * min(1.0, len(self._eval_done) / total)))
        self.progress.setFormat(f"{result.node_id}: {result.status}   ({len(self._eval_done)}/{total} nodes)")

    def _on_eval_finished(self, report: EvalReport) -> None:
        self.cancel_button.setEnabled(self.worker.is_busy)
        if getattr(report, "superseded", False):
            return  # a newer snapshot is already being evaluated
        if getattr(report, "tag", self._generation) != self._generation:
            return  # belongs to a document that has been replaced since
        internal = getattr(report, "internal_error", "")
        if internal:
            self.log("error", f"evaluation failed: {internal}")
        self.last_report = report
        self.eval_count += 1
        self.progress.setValue(0 if report.cancelled else 1000)
        self.progress.setFormat("cancelled" if report.cancelled else f"done in {report.seconds:.2f} s")
        self._log_report(report)
        if not report.cancelled:
            self.editor.set_results(report.results)
            self.inspector.set_results(report.results, report.outputs)
            self.update_viewport()
        self.evaluation_finished.emit(report)

    def _log_report(self, report: EvalReport) -> None:
        by_status: dict[str, list[str]] = {}
        for r in report.results.values():
            item = f"{r.node_id} ({r.seconds:.2f} s)" if r.status == "evaluated" else r.node_id
            by_status.setdefault(r.status, []).append(item)
        parts = [f"{status}: {', '.join(items)}" for status, items in by_status.items()]
        head = "evaluation cancelled" if report.cancelled else f"evaluated in {report.seconds:.2f} s"
        self.log("info", f"{head} — " + "; ".join(parts) if parts else head)
        for nid, err in report.errors.items():
            self.log("error", err)
        for warning in report.warnings.values():
            self.log("warning", warning)
