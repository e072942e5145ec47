"""Typed values run when they are complete: a few lines of script the page runs once.

Viser's text and number boxes send every keystroke to the server (typing "120" would run
1, then 12, then 120), and its number boxes (Mantine's) drop what is not part of a plain
number (``1e3`` would become 13). The script, given to the page in a hidden HTML element
(Viser has no other way to add behaviour to its page), holds a box's keystrokes back from
Viser's client and lets the value go, once, on Enter or when the box loses focus after an
edit (the browser's ``change`` event):

* a gain's box (its label ends with :data:`TYPED_SUFFIX`): its text goes to Viser's client,
  which sends it as the box's value;
* every other box that takes numbers — the number box beside a slider (a gain's, the
  periods', the playback's) and a number box of the run's settings (one of a vector's three
  included): its text, exactly as typed, goes through the hidden box labelled
  :data:`CHANNEL_LABEL` as ``{"page": id, "items": [[n, label, index, text], …]}`` (the
  last few items, numbered, so that two sent within Viser's 50-ms throttle both arrive);
  the server reads it as the gain boxes are read (exponent notation as typed) and takes it,
  or names what it refuses next to the control (:class:`~twolink_pin.tuning.typed.Channel`).
  A box left without an edit sends nothing: a value shown rounded (``160`` for
  ``159.99999999999997``) keeps running exactly;
* while a slider or a box has the focus, the hidden box labelled :data:`FOCUS_LABEL`
  holds ``1`` (else ``0``): the tuner holds the arm's playback still then, so a key press
  on a control never waits behind the 3-D view.

The script keys on what Viser's client renders (a ``label`` beside the input, Mantine's
class names); ``tests/test_tune_page.py`` types into a real page and checks that nothing
runs before Enter and that a slider's box runs what is typed.
"""

from __future__ import annotations

import html

TYPED_SUFFIX = " ="
"""The end of a gain box's label (``kp =``): the script knows the box by it."""
FOCUS_LABEL = "(control focused)"
"""The label of the hidden box the script tells whether a control has the focus."""
CHANNEL_LABEL = "(typed into a box)"
"""The label of the hidden box the script sends a number box's typed text through."""

SCRIPT = r"""
if (!window.twolinkTyped) {
  window.twolinkTyped = true;
  var suffix = %SUFFIX%;
  var focusLabel = %FOCUS%;
  var channelLabel = %CHANNEL%;
  var page = Math.random().toString(36).slice(2) + Date.now().toString(36);
  var sentCount = 0;
  var recent = [];
  var rowOf = function (el) {
    var n = el;
    for (var i = 0; i < 12 && n; i++) {
      n = n.parentElement;
      if (n && n.querySelector('label')) return n;
    }
    return null;
  };
  var labelOf = function (el) {
    var row = rowOf(el);
    return row ? (row.querySelector('label').textContent || '') : '';
  };
  var kind = function (el) {
    if (!(el instanceof HTMLInputElement) || el.type === 'checkbox') return null;
    var row = rowOf(el);
    if (!row) return null;
    var text = row.querySelector('label').textContent || '';
    if (text.slice(-suffix.length) === suffix) return 'typed';
    if (el.closest('.mantine-NumberInput-root')) return 'number';
    return null;
  };
  var hidden = {};
  var hiddenBox = function (label) {
    var known = hidden[label];
    if (known && known.isConnected) return known;
    var l = Array.from(document.querySelectorAll('label')).find(function (e) { return e.textContent === label; });
    var n = l;
    for (var i = 0; i < 12 && n && !n.querySelector('input'); i++) n = n.parentElement;
    if (!n || !n.querySelector('input')) return null;
    if (n.parentElement) n.parentElement.style.display = 'none';
    hidden[label] = n.querySelector('input');
    return hidden[label];
  };
  var hideBoxes = function () { hiddenBox(focusLabel); hiddenBox(channelLabel); };
  new MutationObserver(hideBoxes).observe(document.body, { childList: true, subtree: true });
  hideBoxes();
  var write = function (label, value) {
    var input = hiddenBox(label);
    if (!input || input.value === value) return;
    Object.getOwnPropertyDescriptor(HTMLInputElement.prototype, 'value').set.call(input, value);
    input.dispatchEvent(new Event('input', { bubbles: true }));
  };
  var send = function (el) {
    if (el.value === el.twolinkAtFocus || el.value === el.twolinkSent) return;
    el.twolinkSent = el.value;
    var row = rowOf(el);
    var index = row ? Array.from(row.querySelectorAll('input:not([type=hidden])')).indexOf(el) : 0;
    recent.push([++sentCount, labelOf(el), index, el.value]);
    recent = recent.slice(-8);
    write(channelLabel, JSON.stringify({ page: page, items: recent }));
  };
  window.addEventListener('input', function (e) {
    var k = kind(e.target);
    if (k === 'typed' || k === 'number') e.stopImmediatePropagation();
  }, true);
  window.addEventListener('change', function (e) {
    if (kind(e.target) !== 'number') return;
    e.stopImmediatePropagation();
    send(e.target);
  }, true);
  var control = function (el) {
    return el && el.getAttribute && (el.getAttribute('role') === 'slider' || kind(el) !== null);
  };
  window.addEventListener('focusin', function (e) {
    if (kind(e.target) === 'number') { e.target.twolinkAtFocus = e.target.value; e.target.twolinkSent = null; }
    if (control(e.target)) write(focusLabel, '1');
  }, true);
  window.addEventListener('focusout', function (e) { if (control(e.target)) write(focusLabel, '0'); }, true);
  window.addEventListener('keydown', function (e) {
    if (e.key !== 'Enter') return;
    var k = kind(e.target);
    if (k === 'typed') e.target.dispatchEvent(new Event('change', { bubbles: true }));
    if (k === 'number') { e.preventDefault(); send(e.target); }
  }, true);
}
"""


def typed_html() -> str:
    """The hidden element that runs :data:`SCRIPT` once the page shows it."""
    script = SCRIPT.replace("%SUFFIX%", repr(TYPED_SUFFIX)).replace("%FOCUS%", repr(FOCUS_LABEL))
    script = script.replace("%CHANNEL%", repr(CHANNEL_LABEL)).strip()
    return (
        '<img alt="" style="display:none" src="data:image/gif;base64,AA==" '
        f'onerror="{html.escape(script, quote=True)}">'
    )


__all__ = ["CHANNEL_LABEL", "FOCUS_LABEL", "SCRIPT", "TYPED_SUFFIX", "typed_html"]
