"""Typed values run when they are complete: a few lines of script the page runs once.

Viser's text and number boxes send every keystroke to the server (typing "120" would run
1, then 12, then 120). The script, given to the page in a hidden HTML element (Viser has no
other way to add behaviour to its page), holds a box's keystrokes back from Viser's client
and lets the value go on Enter or when the box loses focus (the browser's ``change`` event):

* a gain's box (its label ends with :data:`TYPED_SUFFIX`) and a number box of the run's
  settings: sent on Enter or blur only; a number box refuses, with the browser's bubble
  next to it (:data:`NUMBER_ONLY`), a key that is no part of a plain number (``e``, a
  letter) instead of dropping it;
* the number box beside a gain's slider: read-only (typing goes to the gain's box, which
  reads exponent notation as typed; the slider's box would read ``1e308`` as 1308);
* while a slider or a gain's box has the focus, the hidden box labelled :data:`FOCUS_LABEL`
  holds ``1`` (else ``0``): the tuner holds the arm's playback still then, so a key press
  on a control never waits behind the 3-D view.

The script keys on what Viser's client renders (a ``label`` beside the input, Mantine's
class names); ``tests/test_tune_browser.py`` types into a real page and checks that
nothing runs before Enter.
"""

from __future__ import annotations

import html

TYPED_SUFFIX = " ="
"""The end of a gain box's label (``kp =``): the script knows the box by it."""
NUMBER_ONLY = "a number here: digits, '.' and '-' (no exponent: type 1e3 as 1000)"
"""What a run setting's number box says of a key that is not part of a plain number (its
box, Mantine's, would drop the letter: ``1e308`` would become 1308)."""
FOCUS_LABEL = "(control focused)"
"""The label of the hidden box the script tells whether a control has the focus."""

SCRIPT = r"""
if (!window.twolinkTyped) {
  window.twolinkTyped = true;
  var suffix = %SUFFIX%;
  var focusLabel = %FOCUS%;
  var NUMBER_ONLY = %NUMBER_ONLY%;
  var rowOf = function (el) {
    var n = el;
    for (var i = 0; i < 12 && n; i++) {
      n = n.parentElement;
      if (n && n.querySelector('label')) return n;
    }
    return null;
  };
  var kind = function (el) {
    if (!(el instanceof HTMLInputElement) || el.type === 'checkbox') return null;
    var row = rowOf(el);
    if (!row) return null;
    var text = row.querySelector('label').textContent || '';
    if (text.slice(-suffix.length) === suffix) return 'typed';
    if (row.querySelector('.mantine-Slider-root')) return 'slider';
    if (el.closest('.mantine-NumberInput-root')) return 'number';
    return null;
  };
  window.addEventListener('input', function (e) {
    var k = kind(e.target);
    if (k === 'typed' || k === 'number') e.stopImmediatePropagation();
  }, true);
  window.addEventListener('beforeinput', function (e) {
    if (kind(e.target) === 'slider') e.preventDefault();
  }, true);
  var focusBox = function () {
    var l = Array.from(document.querySelectorAll('label')).find(function (e) { return e.textContent === focusLabel; });
    var n = l;
    for (var i = 0; i < 12 && n && !n.querySelector('input'); i++) n = n.parentElement;
    if (!n || !n.querySelector('input')) return null;
    if (n.parentElement) n.parentElement.style.display = 'none';
    return n.querySelector('input');
  };
  var tell = function (value) {
    var input = focusBox();
    if (!input || input.value === value) return;
    Object.getOwnPropertyDescriptor(HTMLInputElement.prototype, 'value').set.call(input, value);
    input.dispatchEvent(new Event('input', { bubbles: true }));
  };
  var control = function (el) {
    return el && el.getAttribute && (el.getAttribute('role') === 'slider' || kind(el) === 'typed');
  };
  window.addEventListener('focusin', function (e) { if (control(e.target)) tell('1'); }, true);
  window.addEventListener('focusout', function (e) { if (control(e.target)) tell('0'); }, true);
  var refuse = function (el, text) {
    el.setCustomValidity(text);
    el.reportValidity();
    setTimeout(function () { el.setCustomValidity(''); }, 4000);
  };
  window.addEventListener('keydown', function (e) {
    var k = kind(e.target);
    if (k === 'number' && e.key.length === 1 && !e.ctrlKey && !e.metaKey && !/[0-9.+\-]/.test(e.key)) {
      e.preventDefault();
      refuse(e.target, NUMBER_ONLY);
      return;
    }
    if (e.key === 'Enter' && (k === 'typed' || k === 'number')) {
      e.target.dispatchEvent(new Event('change', { bubbles: true }));
    }
  }, true);
}
"""


def typed_html() -> str:
    """The hidden element that runs :data:`SCRIPT` once the page shows it."""
    script = SCRIPT.replace("%SUFFIX%", repr(TYPED_SUFFIX)).replace("%FOCUS%", repr(FOCUS_LABEL))
    script = script.replace("%NUMBER_ONLY%", repr(NUMBER_ONLY)).strip()
    return (
        '<img alt="" style="display:none" src="data:image/gif;base64,AA==" '
        f'onerror="{html.escape(script, quote=True)}">'
    )


__all__ = ["FOCUS_LABEL", "NUMBER_ONLY", "SCRIPT", "TYPED_SUFFIX", "typed_html"]
